#include "simsoccer/referee/game.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "simsoccer/engine/config.hpp"

namespace simsoccer::referee {

using engine::ConfigNode;

RuleBook loadRuleBook(const std::filesystem::path& file) {
  const ConfigNode root = ConfigNode::loadFile(file);
  root.allowOnly({"rules",
                  "players_per_team",
                  "halves",
                  "half_duration",
                  "half_time_break",
                  "half_time_to_initial",
                  "clock_in_ready_and_set",
                  "ready_duration",
                  "ready_penalty_kick_duration",
                  "kick_off_ball_free",
                  "set_play_duration",
                  "penalty_kick_duration",
                  "mercy_goal_difference",
                  "game_stuck_duration",
                  "goal_area_max_robots",
                  "indirect_kick",
                  "restarts",
                  "fallen",
                  "timeouts",
                  "penalties",
                  "shootout",
                  "message_budget",
                  "gamecontroller"});
  RuleBook r;
  r.name = root["rules"].string();
  r.indirect_kick = root["indirect_kick"].boolean();
  if (auto rs = root.optional("restarts")) {
    rs->allowOnly({"kick_off_direct_goal", "kick_in_indirect", "free_kick_own_goal",
                   "free_kick_distance", "goal_kick_avoidance"});
    r.kick_off_direct_goal = rs->boolean("kick_off_direct_goal", r.kick_off_direct_goal);
    r.kick_in_indirect = rs->boolean("kick_in_indirect", r.kick_in_indirect);
    if (rs->has("free_kick_own_goal")) {
      const std::string v = (*rs)["free_kick_own_goal"].string();
      if (v != "goal" && v != "corner_kick")
        rs->failKey("free_kick_own_goal", "must be goal or corner_kick");
      r.free_kick_own_goal_corner = v == "corner_kick";
    }
    if (rs->has("free_kick_distance")) {
      const ConfigNode d = (*rs)["free_kick_distance"];
      if (d.raw().IsScalar() && d.raw().Scalar() == "centre_circle")
        r.free_kick_distance_centre_circle = true;
      else
        r.free_kick_distance = d.positive();  // metres, or the error names the key
    }
    if (rs->has("goal_kick_avoidance")) {
      const std::string v = (*rs)["goal_kick_avoidance"].string();
      if (v != "free_kick_distance" && v != "penalty_area")
        rs->failKey("goal_kick_avoidance", "must be free_kick_distance or penalty_area");
      r.goal_kick_clears_penalty_area = v == "penalty_area";
    }
  }
  if (auto fl = root.optional("fallen")) {
    fl->allowOnly({"time", "get_up_attempts"});
    if (fl->has("time")) r.fallen_time = (*fl)["time"].positive();
    r.get_up_attempts = fl->integer("get_up_attempts", r.get_up_attempts);
    if (r.get_up_attempts < 1) fl->failKey("get_up_attempts", "must be >= 1");
  }
  const ConfigNode to = root["timeouts"];
  to.allowOnly({"team", "referee", "per_team"});
  r.team_timeout = to["team"].positive();
  r.referee_timeout = to["referee"].positive();
  r.timeouts_per_team = to["per_team"].integer();
  if (r.timeouts_per_team < 0) to.failKey("per_team", "must be >= 0");
  r.source_file = file.string();
  r.players_per_team = root["players_per_team"].integer();
  if (r.players_per_team < 1 || r.players_per_team > static_cast<int>(gc::kMaxPlayers))
    root.failKey("players_per_team", "must be 1..20");
  r.halves = root["halves"].integer();
  if (r.halves != 1 && r.halves != 2) root.failKey("halves", "must be 1 or 2");
  r.half_duration = root["half_duration"].positive();
  r.half_time_break = root["half_time_break"].nonNegative();
  r.half_time_to_initial = root["half_time_to_initial"].nonNegative();
  if (r.half_time_to_initial > r.half_time_break)
    root.failKey("half_time_to_initial", "longer than the half-time break");
  r.clock_in_ready_and_set = root["clock_in_ready_and_set"].boolean();
  r.ready_duration = root["ready_duration"].positive();
  r.ready_penalty_kick_duration = root["ready_penalty_kick_duration"].positive();
  r.kick_off_ball_free = root["kick_off_ball_free"].positive();
  r.set_play_duration = root["set_play_duration"].positive();
  r.penalty_kick_duration = root["penalty_kick_duration"].positive();
  r.mercy_goal_difference = root["mercy_goal_difference"].integer();
  if (r.mercy_goal_difference < 0) root.failKey("mercy_goal_difference", "must be >= 0");
  r.game_stuck_duration = root["game_stuck_duration"].positive();
  r.goal_area_max_robots = root["goal_area_max_robots"].integer();
  const ConfigNode p = root["penalties"];
  p.allowOnly(
      {"base", "increment", "illegal_position_in_set", "motion_in_set", "motion_in_set_in_place"});
  r.penalty_base = p["base"].positive();
  r.penalty_increment = p["increment"].nonNegative();
  r.illegal_position_in_set = p["illegal_position_in_set"].positive();
  r.motion_in_set = p["motion_in_set"].positive();
  r.motion_in_set_in_place = p.boolean("motion_in_set_in_place", true);
  const ConfigNode s = root["shootout"];
  s.allowOnly(
      {"enabled", "kicks_per_team", "shot_duration", "sudden_death", "sudden_death_rounds"});
  r.shootout = s["enabled"].boolean();
  r.shootout_kicks = s["kicks_per_team"].integer();
  if (r.shootout_kicks < 1) s.failKey("kicks_per_team", "must be >= 1");
  r.shootout_shot_duration = s["shot_duration"].positive();
  r.sudden_death = s["sudden_death"].boolean();
  r.sudden_death_rounds = s["sudden_death_rounds"].integer();
  if (r.sudden_death_rounds < 1) s.failKey("sudden_death_rounds", "must be >= 1");
  if (auto g = root.optional("gamecontroller")) {
    g->allowOnly({"version", "competition_type"});
    r.gc_version = g->integer("version", 18);
    if (r.gc_version != 18 && r.gc_version != 19 && r.gc_version != 20)
      g->failKey("version",
                 "must be 18 (SPL, GameController3), 19 (HSL, German Open 2026) or 20 (HSL, "
                 "RoboCup 2026)");
    r.standby = r.gc_version == 18;
    if (g->has("competition_type")) {
      const std::string t = (*g)["competition_type"].string();
      if (r.gc_version == 18) g->failKey("competition_type", "goes with version 19 or 20 (HSL)");
      if (t == "small") r.competition_type = 0;
      else if (t == "middle") r.competition_type = 1;
      else if (t == "large") r.competition_type = 2;
      else g->failKey("competition_type", "must be small, middle or large");
    }
  }
  r.message_budget = root.integer("message_budget", r.message_budget);
  if (r.message_budget < 0 || r.message_budget > 65535)
    root.failKey("message_budget", "must be 0..65535 (a u16 in the packet)");
  return r;
}

const char* stateName(gc::State s) {
  switch (s) {
    case gc::State::Initial:
      return "INITIAL";
    case gc::State::Ready:
      return "READY";
    case gc::State::Set:
      return "SET";
    case gc::State::Playing:
      return "PLAYING";
    case gc::State::Finished:
      return "FINISHED";
    case gc::State::Standby:
      return "STANDBY";
  }
  return "?";
}

const char* setPlayName(gc::SetPlay p) {
  switch (p) {
    case gc::SetPlay::None:
      return "NONE";
    case gc::SetPlay::GoalKick:
      return "GOAL_KICK";
    case gc::SetPlay::PushingFreeKick:
      return "PUSHING_FREE_KICK";
    case gc::SetPlay::CornerKick:
      return "CORNER_KICK";
    case gc::SetPlay::KickIn:
      return "KICK_IN";
    case gc::SetPlay::PenaltyKick:
      return "PENALTY_KICK";
  }
  return "?";
}

Game::Game(const RuleBook& rules, const std::array<TeamSetup, 2>& teams, int kick_off_team)
    : rules_(rules), teams_(teams) {
  if (kick_off_team != 0 && kick_off_team != 1)
    throw std::invalid_argument("the kick-off team is 0 or 1");
  first_half_kick_off_ = kick_off_team;
  timeouts_left_ = {rules.timeouts_per_team, rules.timeouts_per_team};
  kicking_team_ = kick_off_team;
  half_clock_ = rules.half_duration;
  for (auto& team : players_)
    for (size_t n = static_cast<size_t>(rules.players_per_team); n < gc::kMaxPlayers; ++n)
      team[n].penalty = gc::Penalty::Substitute;  // numbers beyond the team size
}

const char* eventName(EventType t) {
  switch (t) {
    case EventType::State:
      return "state";
    case EventType::Half:
      return "half";
    case EventType::GameOver:
      return "game_over";
    case EventType::Shootout:
      return "shootout";
    case EventType::Shot:
      return "shot";
    case EventType::ShotOver:
      return "shot_over";
    case EventType::Goal:
      return "goal";
    case EventType::SetPlay:
      return "set_play";
    case EventType::Penalty:
      return "penalty";
    case EventType::Unpenalise:
      return "unpenalise";
    case EventType::Timeout:
      return "timeout";
    case EventType::DropBall:
      return "drop_ball";
    case EventType::Substitute:
      return "substitute";
    case EventType::Pushing:
      return "pushing";
    case EventType::BallContact:
      return "ball_contact";
    case EventType::Placement:
      return "placement";
    case EventType::GoalDisallowed:
      return "goal_disallowed";
    case EventType::IllegalPosition:
      return "illegal_position";
    case EventType::Inactive:
      return "inactive";
    case EventType::Advisory:
      return "advisory";
  }
  return "?";
}

void Game::log(EventType type, int team, int player, const std::string& detail) {
  events_.push_back({time_, type, team, player, detail});
}

void Game::enter(gc::State s, const std::string& why) {
  state_ = s;
  log(EventType::State, -1, 0, std::string(stateName(s)) + (why.empty() ? "" : ": " + why));
}

Game::Player& Game::player(int team, int number) {
  if (team < 0 || team > 1 || number < 1 || number > static_cast<int>(gc::kMaxPlayers))
    throw std::out_of_range("team 0/1 and player 1..20");
  return players_[static_cast<size_t>(team)][static_cast<size_t>(number - 1)];
}
const Game::Player& Game::player(int team, int number) const {
  return const_cast<Game*>(this)->player(team, number);
}

double Game::penaltyTime(int team, int number) const {
  return player(team, number).remaining;
}
gc::Penalty Game::penalty(int team, int number) const {
  return player(team, number).penalty;
}

bool Game::halfClockRuns() const {
  if (state_ == gc::State::Playing) return true;
  if (state_ == gc::State::Ready || state_ == gc::State::Set)
    return rules_.clock_in_ready_and_set && half_started_;
  return false;
}

void Game::advance(double dt) {
  if (!(dt > 0.0)) return;
  time_ += dt;
  if (game_over_) return;

  // Penalty timers run only in Ready and Playing; an expired penalty is
  // lifted (the simulator is its own GameController operator).
  if (state_ == gc::State::Ready || state_ == gc::State::Playing) {
    for (int t = 0; t < 2; ++t)
      for (int n = 1; n <= static_cast<int>(gc::kMaxPlayers); ++n) {
        Player& p = player(t, n);
        if (p.penalty == gc::Penalty::None || p.penalty == gc::Penalty::Substitute) continue;
        p.remaining = std::max(0.0, p.remaining - dt);
        if (p.remaining == 0.0) unpenalise(t, n);
      }
  }

  if (phase_ == gc::GamePhase::PenaltyShoot) {
    // The shot clock counts only in Playing; at 0 the kick is over.
    if (state_ == gc::State::Playing) {
      half_clock_ -= dt;
      if (half_clock_ <= 0.0)
        endShot(shot_kicked_ ? ShotOutcome::Other : ShotOutcome::NoKick, "shot time over");
    }
    return;
  }

  switch (state_) {
    case gc::State::Ready:
      if (halfClockRuns()) half_clock_ -= dt;
      secondary_ -= dt;
      if (secondary_ <= 0.0) {
        secondary_ = 0.0;
        set();
      }
      break;
    case gc::State::Set:
      if (halfClockRuns()) half_clock_ -= dt;
      break;
    case gc::State::Playing:
      half_clock_ -= dt;
      if (secondary_ > 0.0) {
        secondary_ -= dt;
        if (secondary_ <= 0.0) ballFree();  // the kick-off or set play's time is up
      }
      break;
    case gc::State::Finished:
      if (half_ == Half::First && rules_.halves == 2) {
        secondary_ -= dt;
        if (rules_.half_time_break - secondary_ >= rules_.half_time_to_initial - 1e-9) {
          // Second half: sides swapped, the other team kicks off, penalties lifted.
          half_ = Half::Second;
          sides_swapped_ = true;
          half_clock_ = rules_.half_duration;
          half_started_ = false;
          kicking_team_ = 1 - first_half_kick_off_;
          kick_off_pending_ = true;
          // The break's timer runs on into the second half's Initial (GameController3's
          // SwitchHalf leaves it, counting below 0 when the break is over).
          break_timer_ = true;
          for (int t = 0; t < 2; ++t)
            for (int n = 1; n <= static_cast<int>(gc::kMaxPlayers); ++n)
              if (player(t, n).penalty != gc::Penalty::Substitute) player(t, n) = Player{};
          log(EventType::Half, -1, 0, "second half");
          enter(gc::State::Initial, "half-time");
        }
      }
      break;
    case gc::State::Initial:
    case gc::State::Standby:
      if (break_timer_ && phase_ != gc::GamePhase::Timeout) secondary_ -= dt;
      break;
  }
  if (phase_ == gc::GamePhase::Timeout) secondary_ = std::max(0.0, secondary_ - dt);
  if (half_clock_ <= 0.0 &&
      (state_ == gc::State::Ready || state_ == gc::State::Set || state_ == gc::State::Playing)) {
    half_clock_ = 0.0;
    endHalf();
  }
}

void Game::endHalf() {
  set_play_ = gc::SetPlay::None;
  kicking_team_ = -1;  // 255 on the wire until the next kick-off is known
  secondary_ = 0.0;
  // Timed penalties end with the half.
  for (auto& team : players_)
    for (Player& p : team)
      if (p.penalty != gc::Penalty::Substitute) p = Player{};
  log(EventType::Half, -1, 0, half_ == Half::First ? "end of the first half" : "end of the second half");
  enter(gc::State::Finished, "end of half");
  if (half_ == Half::First && rules_.halves == 2) {
    secondary_ = rules_.half_time_break;
  } else {
    game_over_ = true;
    if (score_[0] != score_[1]) winner_ = score_[0] > score_[1] ? 0 : 1;
    log(EventType::GameOver, -1, 0,
        score_[0] == score_[1] ? "draw" : (score_[0] > score_[1] ? "team 0 wins" : "team 1 wins"));
  }
}

const char* shotOutcomeName(ShotOutcome o) {
  switch (o) {
    case ShotOutcome::Goal:
      return "goal";
    case ShotOutcome::Saved:
      return "saved";
    case ShotOutcome::Post:
      return "post";
    case ShotOutcome::Wide:
      return "wide";
    case ShotOutcome::Other:
      return "other";
    case ShotOutcome::NoKick:
      return "no kick";
  }
  return "?";
}

void Game::startShootout(int first_team, std::optional<int> kicks_per_team, uint64_t coin_seed) {
  if (first_team != 0 && first_team != 1) throw std::invalid_argument("shoot-out: team 0 or 1");
  const bool after_draw = game_over_ && !winner_ && phase_ == gc::GamePhase::Normal;
  const bool stand_alone = state_ == gc::State::Initial && !half_started_ && half_ == Half::First &&
                           phase_ == gc::GamePhase::Normal;
  if (!after_draw && !stand_alone)
    throw std::logic_error("the shoot-out follows a drawn game, or starts a penalty-kick scenario");
  if (after_draw && !rules_.shootout) throw std::logic_error("this rule book has no shoot-out");
  shootout_kicks_ = kicks_per_team.value_or(rules_.shootout_kicks);
  if (shootout_kicks_ < 1) throw std::invalid_argument("shoot-out: kicks per team must be >= 1");
  first_shooter_ = first_team;
  coin_seed_ = coin_seed;
  half_ = Half::PenaltyShootout;
  phase_ = gc::GamePhase::PenaltyShoot;
  game_over_ = false;
  // The score carries on: shoot-out goals add to it (as GC3); the result of
  // the shoot-out itself comes from the kicks' outcomes.
  shots_ = {0, 0};
  outcomes_ = {};
  set_play_ = gc::SetPlay::None;
  secondary_ = 0.0;
  half_clock_ = rules_.shootout_shot_duration;
  kicking_team_ = first_team;
  log(EventType::Shootout, first_team, 0,
      std::to_string(shootout_kicks_) + " kicks per team, team " + std::to_string(first_team) +
          " first");
  enter(gc::State::Initial, "penalty shoot-out");
}

void Game::shootoutKick(int striker, int keeper) {
  if (!shootoutOpen()) throw std::logic_error("no open shoot-out");
  if (state_ != gc::State::Initial && state_ != gc::State::Finished)
    throw std::logic_error("the next kick comes after the previous one ended");
  const int kicks = shots_[0] + shots_[1];
  const int team = kicks % 2 == 0 ? first_shooter_ : 1 - first_shooter_;
  if (striker < 1 || striker > static_cast<int>(gc::kMaxPlayers))
    throw std::invalid_argument("shoot-out: striker number out of range");
  if (keeper < 0 || keeper > static_cast<int>(gc::kMaxPlayers))
    throw std::invalid_argument("shoot-out: keeper number out of range");
  // Everyone but the two players is a substitute for this kick.
  for (int t = 0; t < 2; ++t)
    for (int n = 1; n <= static_cast<int>(gc::kMaxPlayers); ++n)
      player(t, n) = Player{gc::Penalty::Substitute, 0.0};
  player(team, striker) = Player{};
  if (keeper > 0) player(1 - team, keeper) = Player{};
  // GC3 flips its side mapping for every kick after the first: teams[0] swaps.
  if (kicks > 0) sides_swapped_ = !sides_swapped_;
  kicking_team_ = team;
  striker_ = striker;
  keeper_ = keeper;
  shot_kicked_ = false;
  ++shots_[static_cast<size_t>(team)];
  half_clock_ = rules_.shootout_shot_duration;
  log(EventType::Shot, team, striker,
      "kick " + std::to_string(shots_[static_cast<size_t>(team)]) + ", keeper " +
          std::to_string(keeper));
  enter(gc::State::Set, "shoot-out kick");
}

void Game::shotKicked() {
  shot_kicked_ = true;
}

void Game::finishShot(ShotOutcome outcome) {
  if (outcome == ShotOutcome::Goal)
    throw std::invalid_argument("a scored kick goes through goal()");
  if (phase_ != gc::GamePhase::PenaltyShoot || state_ != gc::State::Playing)
    throw std::logic_error("no shoot-out kick is running");
  endShot(outcome, shotOutcomeName(outcome));
}

void Game::endShot(ShotOutcome outcome, const std::string& why) {
  outcomes_[static_cast<size_t>(kicking_team_)].push_back(outcome);
  log(EventType::ShotOver, kicking_team_, striker_, why);
  enter(gc::State::Finished, "shoot-out kick over");
  decideShootout();
}

void Game::decideShootout() {
  const int a = first_shooter_, b = 1 - first_shooter_;
  const int k = shootout_kicks_;
  auto goals = [&](int t, int upto) {
    int g = 0;
    const auto& o = outcomes_[static_cast<size_t>(t)];
    for (int i = 0; i < std::min(upto, static_cast<int>(o.size())); ++i)
      g += o[static_cast<size_t>(i)] == ShotOutcome::Goal;
    return g;
  };
  const int na = static_cast<int>(outcomes_[static_cast<size_t>(a)].size());
  const int nb = static_cast<int>(outcomes_[static_cast<size_t>(b)].size());
  auto decide = [&](int team, const std::string& why) {
    winner_ = team;
    game_over_ = true;
    log(EventType::GameOver, team, 0, "team " + std::to_string(team) + " wins the shoot-out (" + why + ")");
  };
  if (na <= k && nb <= k) {
    // Regular kicks: decided once a team can no longer catch up.
    const int ga = goals(a, k), gb = goals(b, k);
    if (ga > gb + (k - nb)) return decide(a, std::to_string(ga) + ":" + std::to_string(gb));
    if (gb > ga + (k - na)) return decide(b, std::to_string(gb) + ":" + std::to_string(ga));
    if (na < k || nb < k) return;
    if (!rules_.sudden_death) {
      game_over_ = true;
      log(EventType::GameOver, -1, 0, "draw after the shoot-out");
      return;
    }
    return;  // level: sudden death
  }
  // Sudden death: a round is complete when both kicked; the better category wins.
  if (na != nb) return;
  const int round = na - k;
  const ShotOutcome oa = outcomes_[static_cast<size_t>(a)].back();
  const ShotOutcome ob = outcomes_[static_cast<size_t>(b)].back();
  if (oa != ob)
    return decide(oa < ob ? a : b, std::string("sudden death: ") + shotOutcomeName(oa) + " vs " +
                                       shotOutcomeName(ob));
  if (round >= rules_.sudden_death_rounds) {
    // A coin toss; mt19937_64's sequence is fixed by the standard, so the
    // same seed gives the same coin on every platform.
    std::mt19937_64 coin(coin_seed_);
    return decide((coin() & 1u) ? b : a, "coin toss");
  }
}

void Game::standby() {
  if (phase_ == gc::GamePhase::PenaltyShoot) throw std::logic_error("no Standby in the shoot-out");
  if (!rules_.standby) throw std::logic_error("this league's GameController has no Standby");
  if (state_ != gc::State::Initial && phase_ != gc::GamePhase::Timeout)
    throw std::logic_error("Standby comes from Initial or a timeout");
  phase_ = gc::GamePhase::Normal;
  enter(gc::State::Standby, "");
}

void Game::startKickOff(int team, const std::string& why) {
  kicking_team_ = team;
  kick_off_pending_ = true;
  set_play_ = gc::SetPlay::None;
  secondary_ = rules_.ready_duration;
  break_timer_ = false;
  enter(gc::State::Ready, why);
}

void Game::ready() {
  if (phase_ == gc::GamePhase::PenaltyShoot)
    throw std::logic_error("the shoot-out goes kick by kick (shootoutKick)");
  if (state_ != gc::State::Initial && state_ != gc::State::Standby &&
      phase_ != gc::GamePhase::Timeout)
    throw std::logic_error("Ready comes from Initial, Standby or a timeout");
  phase_ = gc::GamePhase::Normal;
  startKickOff(kicking_team_, "kick-off");
}

void Game::set() {
  if (state_ != gc::State::Ready) throw std::logic_error("Set comes from Ready");
  secondary_ = 0.0;
  enter(gc::State::Set, "");
}

void Game::playing() {
  if (state_ != gc::State::Set) throw std::logic_error("Playing comes from Set");
  if (phase_ == gc::GamePhase::PenaltyShoot) {
    secondary_ = 0.0;
    enter(gc::State::Playing, "shoot-out kick");
    return;
  }
  half_started_ = true;
  enter(gc::State::Playing, "");
  if (set_play_ == gc::SetPlay::PenaltyKick) {
    secondary_ = rules_.penalty_kick_duration;
  } else if (kick_off_pending_ && kicking_team_ >= 0) {
    secondary_ = rules_.kick_off_ball_free;  // the kick-off: ball free after this or a touch
  } else {
    secondary_ = 0.0;  // a drop ball is in play at once
    kicking_team_ = -1;
  }
  kick_off_pending_ = false;
}

void Game::goal(int team) {
  if (team != 0 && team != 1) throw std::invalid_argument("goal: team 0 or 1");
  if (state_ != gc::State::Playing) throw std::logic_error("goals count in Playing");
  if (phase_ == gc::GamePhase::PenaltyShoot) {
    if (team != kicking_team_)
      throw std::logic_error("in the shoot-out only the kicking team scores");
    ++score_[static_cast<size_t>(team)];
    log(EventType::Goal, team, striker_, std::to_string(score_[0]) + ":" + std::to_string(score_[1]));
    endShot(ShotOutcome::Goal, "goal");
    return;
  }
  ++score_[static_cast<size_t>(team)];
  log(EventType::Goal, team, 0, std::to_string(score_[0]) + ":" + std::to_string(score_[1]));
  if (rules_.mercy_goal_difference > 0 &&
      std::abs(score_[0] - score_[1]) >= rules_.mercy_goal_difference) {
    secondary_ = 0.0;
    set_play_ = gc::SetPlay::None;
    kicking_team_ = -1;
    enter(gc::State::Finished, "mercy rule");
    game_over_ = true;
    winner_ = team;
    log(EventType::GameOver, -1, 0, "mercy rule");
    return;
  }
  startKickOff(1 - team, "goal, kick-off for the other team");
}

void Game::ballFree() {
  if (state_ != gc::State::Playing) return;
  if (set_play_ != gc::SetPlay::None || kicking_team_ >= 0)
    log(EventType::SetPlay, kicking_team_, 0,
        set_play_ == gc::SetPlay::None ? std::string("kick-off over")
                                       : std::string("over: ") + setPlayName(set_play_));
  set_play_ = gc::SetPlay::None;
  kicking_team_ = -1;
  secondary_ = 0.0;
}

void Game::setPlay(gc::SetPlay play, int team) {
  if (team != 0 && team != 1) throw std::invalid_argument("set play: team 0 or 1");
  if (state_ != gc::State::Playing) throw std::logic_error("set plays start in Playing");
  if (play == gc::SetPlay::None) return ballFree();
  kicking_team_ = team;
  set_play_ = play;
  ++set_plays_awarded_;
  log(EventType::SetPlay, team, 0, setPlayName(play));
  if (play == gc::SetPlay::PenaltyKick) {
    // Ready (30 s) and Set before the kick, which then has 30 s in Playing.
    kick_off_pending_ = false;
    secondary_ = rules_.ready_penalty_kick_duration;
    enter(gc::State::Ready, "penalty kick");
  } else {
    secondary_ = rules_.set_play_duration;
  }
}

void Game::penalise(int team, int number, gc::Penalty p) {
  Player& pl = player(team, number);
  if (pl.penalty == gc::Penalty::Substitute) throw std::logic_error("substitutes are not in play");
  double seconds = rules_.penalty_base;
  switch (p) {
    case gc::Penalty::IllegalPositionInSet:
      seconds = rules_.illegal_position_in_set;
      break;
    case gc::Penalty::IllegalMotionInSet:
      seconds = rules_.motion_in_set;
      break;
    case gc::Penalty::IllegalBallContact:
    case gc::Penalty::PlayerPushing:
    case gc::Penalty::IllegalPosition:
    case gc::Penalty::PlayerStance:
    case gc::Penalty::LeavingTheField:
      // Incremental: +10 s for each earlier incremental penalty of the team.
      seconds = rules_.penalty_base +
                rules_.penalty_increment * incremental_[static_cast<size_t>(team)]++;
      break;
    case gc::Penalty::RequestForPickup:
      // It may replace a running penalty: that timer is kept, at least the base time.
      if (pl.penalty != gc::Penalty::None) seconds = std::max(pl.remaining, rules_.penalty_base);
      break;
    case gc::Penalty::Substitute:
    case gc::Penalty::None:
      throw std::invalid_argument("penalise: use substitute() / unpenalise()");
    default:
      break;
  }
  pl.penalty = p;
  pl.remaining = seconds;
  log(EventType::Penalty, team, number,
      std::to_string(static_cast<int>(p)) + " for " +
          std::to_string(static_cast<int>(std::ceil(seconds))) + " s");
}

void Game::unpenalise(int team, int number) {
  Player& pl = player(team, number);
  if (pl.penalty == gc::Penalty::None || pl.penalty == gc::Penalty::Substitute) return;
  pl = Player{};
  log(EventType::Unpenalise, team, number, "");
}

void Game::timeout(std::optional<int> team) {
  if (phase_ == gc::GamePhase::PenaltyShoot) throw std::logic_error("no timeouts in the shoot-out");
  if (state_ == gc::State::Finished) throw std::logic_error("no timeout after the game");
  if (team) {
    if (*team != 0 && *team != 1) throw std::invalid_argument("timeout: team 0 or 1");
    if (state_ == gc::State::Playing) throw std::logic_error("no team timeout while playing");
    if (timeouts_left_[static_cast<size_t>(*team)] <= 0)
      throw std::logic_error("the team has no timeout left");
    --timeouts_left_[static_cast<size_t>(*team)];
    kicking_team_ = 1 - *team;  // the other team gets the kick-off
    secondary_ = rules_.team_timeout;
  } else {
    secondary_ = rules_.referee_timeout;
  }
  break_timer_ = false;
  phase_ = gc::GamePhase::Timeout;
  set_play_ = gc::SetPlay::None;
  log(EventType::Timeout, team ? *team : -1, 0, team ? "team timeout" : "referee timeout");
  enter(gc::State::Initial, "timeout");
}

void Game::dropBall() {
  if (state_ != gc::State::Playing) throw std::logic_error("a drop ball restarts Playing");
  log(EventType::DropBall, -1, 0, "");
  startKickOff(-1, "drop ball");
}

void Game::substitute(int team, int out, int in) {
  Player& leaving = player(team, out);
  Player& coming = player(team, in);
  if (coming.penalty != gc::Penalty::Substitute)
    throw std::logic_error("the incoming player is already in play");
  leaving = Player{gc::Penalty::Substitute, 0.0};
  coming = Player{};
  // The goalkeeper role goes to the incoming player (GC3).
  TeamSetup& setup = teams_[static_cast<size_t>(team)];
  if (setup.goalkeeper == out) setup.goalkeeper = static_cast<uint8_t>(in);
  log(EventType::Substitute, team, in, "for player " + std::to_string(out));
}

void Game::follow(const ControlData& d) {
  const auto index = [&](uint8_t number) {
    for (int t = 0; t < 2; ++t)
      if (teams_[static_cast<size_t>(t)].number == number) return t;
    return -1;
  };
  const int left = index(d.teams[0].team_number);
  if (left < 0 || index(d.teams[1].team_number) != 1 - left)
    throw PacketError("GameController packet for teams " + std::to_string(d.teams[0].team_number) +
                      " and " + std::to_string(d.teams[1].team_number) + ", this game has " +
                      std::to_string(teams_[0].number) + " and " + std::to_string(teams_[1].number));
  sides_swapped_ = left == 1;
  const auto phase = static_cast<gc::GamePhase>(std::min<uint8_t>(d.game_phase, 3));
  const auto state = static_cast<gc::State>(std::min<uint8_t>(d.state, 5));
  const auto set_play = static_cast<gc::SetPlay>(std::min<uint8_t>(d.set_play, 5));
  const Half half = phase == gc::GamePhase::PenaltyShoot
                        ? Half::PenaltyShootout
                        : (d.first_half ? Half::First : Half::Second);
  if (half != half_) log(EventType::Half, -1, 0, "from the GameController");
  half_ = half;
  phase_ = phase;
  const int kicking = d.kicking_team == gc::kKickingTeamNone ? -1 : index(d.kicking_team);
  // (A GameController's packets do not tell a set play awarded again to the same team.)
  if ((set_play != set_play_ || kicking != kicking_team_) && set_play != gc::SetPlay::None) {
    log(EventType::SetPlay, kicking, 0, std::string(setPlayName(set_play)) + " (GameController)");
    ++set_plays_awarded_;
  }
  set_play_ = set_play;
  kicking_team_ = kicking;
  if (state != state_) enter(state, "GameController");
  half_clock_ = d.secs_remaining;
  secondary_ = d.secondary_time;
  for (int side = 0; side < 2; ++side) {
    const TeamInfo& info = d.teams[static_cast<size_t>(side)];
    const int t = side == 0 ? left : 1 - left;
    for (int goal = score_[static_cast<size_t>(t)]; goal < info.score; ++goal)
      log(EventType::Goal, t, 0, "GameController");
    score_[static_cast<size_t>(t)] = info.score;
    if (info.goalkeeper > 0) teams_[static_cast<size_t>(t)].goalkeeper = info.goalkeeper;
    for (int n = 1; n <= static_cast<int>(gc::kMaxPlayers); ++n) {
      Player& p = player(t, n);
      const RobotInfo& r = info.players[static_cast<size_t>(n - 1)];
      const auto penalty = static_cast<gc::Penalty>(r.penalty);
      if (penalty != p.penalty) {
        if (penalty == gc::Penalty::None)
          log(EventType::Unpenalise, t, n, "GameController");
        else if (penalty != gc::Penalty::Substitute)
          log(EventType::Penalty, t, n, "GameController: penalty " + std::to_string(r.penalty));
      }
      p.penalty = penalty;
      p.remaining = r.secs_till_unpenalised;
    }
  }
  // The game is over when the GameController finishes the second half, or a
  // shoot-out or overtime (a shoot-out it starts later opens it again; the
  // officials wait a while before they call the game over).
  game_over_ = state_ == gc::State::Finished &&
               (half_ == Half::Second || phase_ != gc::GamePhase::Normal);
  stopped_ = d.stopped != 0;
  if (game_over_) {
    if (score_[0] != score_[1]) winner_ = score_[0] > score_[1] ? 0 : 1;
  }
}

void Game::setTeamMessagesSent(int team, uint64_t total) {
  const auto t = static_cast<size_t>(team);
  const uint64_t fresh = total > messages_seen_.at(t) ? total - messages_seen_[t] : 0;
  messages_seen_[t] = total;
  // As GameController3 (actions/team_message.rs) and the HSL's: a message counts in Standby,
  // Ready, Set and Playing outside the shoot-out; in Initial, Finished, a timeout or the
  // shoot-out it is free.
  const bool counted = phase_ != gc::GamePhase::PenaltyShoot &&
                       (state_ == gc::State::Standby || state_ == gc::State::Ready ||
                        state_ == gc::State::Set || state_ == gc::State::Playing);
  if (counted) messages_counted_[t] += fresh;
}

int Game::messageBudget(int team) const {
  const uint64_t sent = messages_counted_.at(static_cast<size_t>(team));
  const auto budget = static_cast<uint64_t>(rules_.message_budget);
  return static_cast<int>(sent >= budget ? 0 : budget - sent);
}

ControlData Game::packet(uint8_t packet_number) const {
  ControlData d;
  d.packet_number = packet_number;
  // A play-off ("long") game stops the clock in Ready and Set.
  d.competition_phase = rules_.clock_in_ready_and_set ? 0 : 1;
  d.competition_type = rules_.competition_type;
  // The simulator's referee places the ball at once: play is stopped only
  // when an external (HSL) GameController that is followed says so.
  d.stopped = stopped_ ? 1 : 0;
  d.players_per_team = static_cast<uint8_t>(rules_.players_per_team);
  d.game_phase = static_cast<uint8_t>(phase_);
  d.state = static_cast<uint8_t>(state_);
  d.set_play = static_cast<uint8_t>(set_play_);
  d.first_half = half_ == Half::First ? 1 : 0;
  d.kicking_team =
      kicking_team_ >= 0 ? teams_[static_cast<size_t>(kicking_team_)].number : gc::kKickingTeamNone;
  auto secs = [](double s) {  // rounded up, clamped to the i16 range
    return static_cast<int16_t>(std::clamp(std::ceil(s - 1e-9), -32768.0, 32767.0));
  };
  d.secs_remaining = secs(half_clock_);
  d.secondary_time = secs(secondary_);
  for (int side = 0; side < 2; ++side) {
    const int t = side == 0 ? leftTeam() : 1 - leftTeam();
    const TeamSetup& setup = teams_[static_cast<size_t>(t)];
    TeamInfo& info = d.teams[static_cast<size_t>(side)];
    info.team_number = setup.number;
    info.field_player_colour = setup.field_player_colour;
    info.goalkeeper_colour = setup.goalkeeper_colour;
    info.goalkeeper = setup.goalkeeper;
    info.score = static_cast<uint8_t>(score_[static_cast<size_t>(t)]);
    if (phase_ == gc::GamePhase::PenaltyShoot) {
      info.penalty_shot = static_cast<uint8_t>(shots_[static_cast<size_t>(t)]);
      // Bit i: the team's kick i + 1 scored.
      const auto& kicks = outcomes_[static_cast<size_t>(t)];
      for (size_t i = 0; i < std::min<size_t>(kicks.size(), 16); ++i)
        if (kicks[i] == ShotOutcome::Goal) info.single_shots |= static_cast<uint16_t>(1u << i);
      // The keeper of this kick; a team without one shows its lowest substitute (as GC3).
      uint8_t gk = 0;
      if (t != kicking_team_ && keeper_ > 0) gk = static_cast<uint8_t>(keeper_);
      for (int n = 1; n <= static_cast<int>(gc::kMaxPlayers) && gk == 0; ++n)
        if (player(t, n).penalty == gc::Penalty::Substitute) gk = static_cast<uint8_t>(n);
      if (striker_ > 0) info.goalkeeper = gk;
    }
    info.message_budget = static_cast<uint16_t>(messageBudget(t));
    for (int n = 1; n <= static_cast<int>(gc::kMaxPlayers); ++n) {
      const Player& p = player(t, n);
      info.players[static_cast<size_t>(n - 1)] = {
          static_cast<uint8_t>(p.penalty),
          static_cast<uint8_t>(std::clamp(std::ceil(p.remaining - 1e-9), 0.0, 255.0))};
    }
  }
  return d;
}

}  // namespace simsoccer::referee
