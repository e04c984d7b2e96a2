// Shared by the referee tests: the SPL rule book and two teams.
#pragma once

#include <array>

#include "simsoccer/referee/game.hpp"
#include "test_support.hpp"

namespace simsoccer::test {

inline referee::RuleBook splRules() {
  return referee::loadRuleBook(sourceDir() / "configs" / "rules" / "spl.yaml");
}

// Team numbers 13 (blue) and 5 (red).
inline std::array<referee::TeamSetup, 2> twoTeams() {
  std::array<referee::TeamSetup, 2> t;
  t[0].number = 13;
  t[0].field_player_colour = 0;
  t[1].number = 5;
  t[1].field_player_colour = 1;
  return t;
}

}  // namespace simsoccer::test
