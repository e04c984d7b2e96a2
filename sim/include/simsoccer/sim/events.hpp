// Typed events of a period, read after it (as Box2D's events after the
// step): the referee's calls, referee::RefereeEvent with its EventType.
#pragma once

#include "simsoccer/referee/game.hpp"

namespace simsoccer::sim {

using Event = referee::RefereeEvent;
using EventType = referee::EventType;

}  // namespace simsoccer::sim
