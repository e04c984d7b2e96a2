#include "simsoccer/match/match_session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/engine/state_hash.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/referee/gamecontroller.hpp"
#include "simsoccer/robots/robot_model.hpp"

namespace simsoccer::match {
namespace {

std::string fileBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Loads what the match's agents will load, for every robot model of the scenario: a bad
// behaviour file, keyframe motion or gait stops the match here, before anything starts, not
// each agent process after the match began. With no motions folder the agents use their own
// default one, and only the behaviour file is checked.
void checkAgentFiles(const MatchConfig& c, const world::Scenario& scenario) {
  const agents::BehaviourConfig behaviour = c.agent_config.empty()
                                                ? agents::BehaviourConfig{}
                                                : agents::loadBehaviourConfig(c.agent_config);
  if (c.agent_motions.empty()) return;
  std::set<std::filesystem::path> models;
  for (const world::RobotPlacement& r : scenario.robots)
    models.insert(r.model_file.empty() ? scenario.robot_model_file
                                       : std::filesystem::path(r.model_file));
  if (models.empty()) return;
  const fields::FieldModel field = fields::loadFieldModel(scenario.field_file);
  for (const std::filesystem::path& file : models) {
    const robots::RobotModel model = robots::loadRobotModel(file);
    agents::SoccerAgent(model, behaviour, field, agents::motionsFolder(c.agent_motions, model), {});
  }
}

}  // namespace

std::vector<LolaPlayer> parseLolaPlayers(const std::string& list) {
  std::vector<LolaPlayer> out;
  std::size_t at = 0;
  while (at <= list.size()) {
    const std::size_t end = std::min(list.find(',', at), list.size());
    const std::string entry = list.substr(at, end - at);
    LolaPlayer p;
    char rest = 0;
    if (std::sscanf(entry.c_str(), "%d:%d%c", &p.team_number, &p.player, &rest) != 2 ||
        p.team_number < 0 || p.team_number > 254 || p.player < 1 || p.player > 20)
      throw std::invalid_argument("'" + entry +
                                  "' is not TEAM:PLAYER (a GameController team number 0..254 and "
                                  "a player number 1..20)");
    out.push_back(p);
    at = end + 1;
  }
  return out;
}

void checkTeamSizes(const referee::RuleBook& rules, const world::Scenario& scenario) {
  for (int team = 0; team < 2; ++team) {
    const auto players =
        std::count_if(scenario.robots.begin(), scenario.robots.end(),
                      [&](const world::RobotPlacement& r) { return r.team == team; });
    if (players > rules.players_per_team)
      throw engine::ConfigError(rules.source_file, "players_per_team",
                                std::to_string(rules.players_per_team) + ", but " +
                                    scenario.source_file + " has " + std::to_string(players) +
                                    " robots in team " + std::to_string(team));
  }
}

MatchConfig loadMatchConfig(const std::filesystem::path& file) {
  const engine::ConfigNode root = engine::ConfigNode::loadFile(file);
  // Another kind of file (a scenario, say) is named as such before its keys are judged.
  if (!root.has("match") && !root.has("penalty"))
    root.fail(
        "not a match config: needs `match: NAME` (a game) or `penalty: NAME` (a "
        "penalty-kick scenario)" +
        std::string(root.has("field") ? "; this looks like a scenario, which a match "
                                        "config names with `scenario:`"
                                      : ""));
  root.allowOnly({"match", "penalty", "scenario", "rules", "half_duration", "half_time_break",
                  "teams", "agents", "team_messages", "lockstep", "set_duration", "video", "seed",
                  "kicks", "lola"});
  MatchConfig c;
  c.file = file.string();
  if (root.has("match"))
    c.name = root["match"].string();
  else if (root.has("penalty"))
    c.name = root["penalty"].string();
  else
    root.fail("needs `match: NAME` (a game) or `penalty: NAME` (a penalty-kick scenario)");
  auto path = [&](const char* key) {
    const engine::ConfigNode n = root[key];
    const auto p = engine::resolveBeside(c.file, n.string());
    if (!std::filesystem::exists(p)) n.fail("no such file: " + p.string());
    return p;
  };
  c.scenario = path("scenario");
  c.rules = path("rules");
  if (root.has("half_duration")) c.half_duration = root["half_duration"].positive();
  if (root.has("half_time_break")) c.half_time_break = root["half_time_break"].nonNegative();
  if (root.has("teams")) {
    const auto t = root["teams"].numbers(2);
    for (size_t i = 0; i < 2; ++i) {
      if (t[i] < 0 || t[i] > 254 || t[i] != std::floor(t[i]))
        root["teams"].fail("GameController team numbers are whole numbers 0..254");
      c.team_numbers[i] = static_cast<int>(t[i]);
    }
    if (c.team_numbers[0] == c.team_numbers[1])
      root["teams"].fail("the two teams need different numbers");
  }
  if (auto a = root.optional("agents")) {
    a->allowOnly({"config", "motions", "role", "get_up", "restart_limit"});
    if (a->has("config")) {
      c.agent_config = engine::resolveBeside(c.file, (*a)["config"].string());
      if (!std::filesystem::exists(c.agent_config))
        (*a)["config"].fail("no such file: " + c.agent_config.string());
    }
    if (a->has("motions")) {
      c.agent_motions = engine::resolveBeside(c.file, (*a)["motions"].string());
      if (!std::filesystem::is_directory(c.agent_motions))
        (*a)["motions"].fail("no such folder: " + c.agent_motions.string());
    }
    if (a->has("role")) {
      c.role = (*a)["role"].string();
      if (!agents::roleFromName(c.role))
        (*a)["role"].fail(
            "must be auto, striker, supporter, defender, goalkeeper, penalty-kicker or "
            "penalty-goalkeeper");
    }
    c.get_up = a->boolean("get_up", c.get_up);
    c.restart_limit = a->integer("restart_limit", c.restart_limit);
    if (c.restart_limit < 0) (*a)["restart_limit"].fail("must be >= 0");
  }
  if (c.agent_motions.empty()) {
    const std::filesystem::path beside = engine::resolveBeside(c.file, "motions");
    if (std::filesystem::is_directory(beside)) c.agent_motions = beside;
  }
  if (auto t = root.optional("team_messages")) {
    t->allowOnly({"delay", "loss"});
    c.message_delay = t->number("delay", 0.0);
    c.message_loss = t->number("loss", 0.0);
    if (c.message_delay < 0) (*t)["delay"].fail("must be >= 0");
    if (c.message_loss < 0 || c.message_loss > 1) (*t)["loss"].fail("must be within 0..1");
  }
  if (auto l = root.optional("lockstep")) {
    l->allowOnly({"timeout"});
    c.command_timeout = (*l)["timeout"].positive();
  }
  if (root.has("set_duration")) c.set_duration = root["set_duration"].positive();
  if (auto v = root.optional("video")) {
    v->allowOnly({"enabled", "fps", "size", "position", "look_at", "horizontal_fov"});
    c.video.enabled = v->boolean("enabled", true);
    if (v->has("fps")) c.video.fps = (*v)["fps"].positive();
    if (v->has("size")) {
      const auto s = (*v)["size"].numbers(2);
      if (s[0] < 16 || s[1] < 16 || s[0] > 4096 || s[1] > 4096)
        (*v)["size"].fail("width and height must be 16..4096 px");
      c.video.width = static_cast<int>(s[0]);
      c.video.height = static_cast<int>(s[1]);
    }
    if (v->has("position")) c.video.position = (*v)["position"].vec3();
    if (v->has("look_at")) c.video.look_at = (*v)["look_at"].vec3();
    if (v->has("horizontal_fov")) {
      c.video.horizontal_fov = (*v)["horizontal_fov"].positive();
      if (c.video.horizontal_fov >= 3.0)
        (*v)["horizontal_fov"].fail("must be under 3 rad (a pinhole camera sees less than pi)");
    }
    if ((c.video.look_at - c.video.position).norm() < 1e-3)
      (v->has("look_at") ? (*v)["look_at"] : (*v)["position"])
          .fail("the camera must look at a point away from its position");
  }
  if (auto l = root.optional("lola")) {
    l->allowOnly({"robots", "client", "connect_timeout", "reconnect_timeout", "image_port",
                  "network", "identities", "tick_in_battery"});
    if (auto ids = l->optional("identities")) {
      for (const auto& [robot, node] : ids->entries()) {
        std::vector<LolaPlayer> players;
        try {
          players = parseLolaPlayers(robot);
        } catch (const std::invalid_argument& e) {
          node.fail(std::string("not a robot T:P: ") + e.what());
        }
        if (players.size() != 1) node.fail("one robot T:P");
        node.allowOnly({"body_id", "body_version", "head_id", "head_version"});
        lola::RobotIdentity id = lola::defaultIdentity(players[0].team_number, players[0].player);
        for (auto [key, field] : {std::pair{"body_id", &id.body_id}, {"body_version", &id.body_version},
                                  {"head_id", &id.head_id}, {"head_version", &id.head_version}}) {
          if (node.has(key)) *field = node[key].string();
          try {  // team code checks these strings: refused here, not on the wire
            lola::checkIdentity(id);
          } catch (const std::invalid_argument& e) {
            if (node.has(key) && std::string(e.what()).find(key) != std::string::npos)
              node.failKey(key, e.what());
          }
        }
        c.lola.identities[robot] = id;
      }
    }
    c.lola.network = l->boolean("network", false);
    c.lola.tick_in_battery = l->boolean("tick_in_battery", true);
    if (l->has("image_port")) {
      const int port = (*l)["image_port"].integer();
      if (port < 1 || port > 65000) (*l)["image_port"].fail("must be 1..65000");
      c.lola.image_port = static_cast<uint16_t>(port);
    }
    for (const engine::ConfigNode& r : (*l)["robots"].items()) {
      try {
        const auto players = parseLolaPlayers(r.string());
        c.lola.robots.insert(c.lola.robots.end(), players.begin(), players.end());
      } catch (const std::invalid_argument& e) {
        r.fail(e.what());
      }
    }
    if (l->has("client"))
      for (const engine::ConfigNode& a : (*l)["client"].items()) c.lola.client.push_back(a.string());
    if (l->has("connect_timeout")) c.lola.connect_timeout = (*l)["connect_timeout"].positive();
    if (l->has("reconnect_timeout"))
      c.lola.reconnect_timeout = (*l)["reconnect_timeout"].nonNegative();
  }
  if (root.has("seed") && root["seed"].integer() < 0) root["seed"].fail("must be >= 0");
  c.seed = static_cast<uint64_t>(root.integer("seed", 1));
  if (root.has("match") && root.has("kicks")) root["kicks"].fail("belongs to a penalty config (`penalty: NAME`)");
  if (root.has("penalty")) {
    // A penalty kick has no halves: these would be read by nobody.
    for (const char* key : {"half_duration", "half_time_break"})
      if (root.has(key)) root[key].fail("belongs to a match; a penalty kick lasts the rule book's shot_duration");
    c.penalty_kicks = root.integer("kicks", 5);
    if (c.penalty_kicks < 1) root["kicks"].fail("must be >= 1");
  }
  // The rule book and scenario must load (their own errors name them).
  const world::Scenario scenario = world::loadScenario(c.scenario);
  checkTeamSizes(referee::loadRuleBook(c.rules), scenario);
  checkAgentFiles(c, scenario);
  const std::string bytes = fileBytes(file) + fileBytes(c.scenario) + fileBytes(c.rules);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(engine::hashBytes(bytes.data(), bytes.size())));
  c.hash = hex;
  return c;
}

MatchSession::MatchSession(const MatchConfig& config, uint64_t seed, int solver_threads)
    : config_(config) {
  world::Scenario s = world::loadScenario(config.scenario);
  s.seed = seed;
  if (solver_threads > 0) s.physics.threads = solver_threads;
  if (!config.lola.robots.empty()) {
    // LoLA's cycle is 12 ms; the physics step must divide it. 6 ms keeps every
    // bench motion figure (12 ms: the striker 78 %, docs/benchmarks.md).
    const double cycle = 0.012;
    const double steps = cycle / s.physics.dt;
    if (std::abs(steps - std::round(steps)) > 1e-6) s.physics.dt = 0.006;
    s.physics.control_period = cycle;
  }
  if (!s.perception.enabled)  // not switched on behind the scenario's back
    throw engine::ConfigError(config.scenario.string(), "perception",
                              "a match's agents see through perception: turn it on");
  world_ = std::make_unique<world::World>(s);
  touches_.emplace(world_->scenario().physics.dt);
  referee::RuleBook rules = referee::loadRuleBook(config.rules);
  if (config.half_duration) rules.half_duration = *config.half_duration;
  if (config.half_time_break) {
    rules.half_time_break = *config.half_time_break;
    rules.half_time_to_initial = std::min(rules.half_time_to_initial, *config.half_time_break);
  }
  sim::OfficialsConfig oc = sim::OfficialsConfig::forTeams(
      static_cast<uint8_t>(config.team_numbers[0]), static_cast<uint8_t>(config.team_numbers[1]));
  oc.referee.set_duration = config.set_duration;
  oc.referee.auto_placement = true;  // robots still walking at Set are placed, as a human referee would
  oc.penalty_kick_trial = config.penalty_kicks > 0;
  oc.seed = seed;
  oc.external_gc_port = config.external_gc_port;
  officials_ = std::make_unique<sim::GameOfficials>(*world_, rules, oc);
  for (world::RobotId r = 0; r < world_->robotCount(); ++r) {
    RobotRecord rec;
    rec.team = world_->robot(r).team;
    rec.number = world_->robot(r).number;
    rec.last = world_->torsoPose(r).translation();
    records_.push_back(rec);
  }
  for (size_t i = 0; i < config.lola.robots.size(); ++i) {
    const LolaPlayer& p = config.lola.robots[i];
    // A robot named with --lola is the command line's fault, not the file's.
    const bool option = i >= config.lola.robots.size() - config.lola.from_option;
    const auto fail = [&](const std::string& reason) {
      if (option) throw std::invalid_argument("--lola: " + reason);
      throw engine::ConfigError(config.file, "lola.robots", reason);
    };
    int team = -1;
    for (int t = 0; t < 2; ++t)
      if (config.team_numbers[static_cast<size_t>(t)] == p.team_number) team = t;
    std::optional<world::RobotId> found;
    for (world::RobotId r = 0; r < world_->robotCount(); ++r)
      if (world_->robot(r).team == team && world_->robot(r).number == p.player) found = r;
    if (!found)
      fail("no robot " + std::to_string(p.team_number) + ":" + std::to_string(p.player) +
           " in the match (teams " + std::to_string(config.team_numbers[0]) + " and " +
           std::to_string(config.team_numbers[1]) + ")");
    for (world::RobotId r : lola_robots_)
      if (r == *found)
        fail("robot " + std::to_string(p.team_number) + ":" + std::to_string(p.player) +
             " is named twice");
    lola_robots_.push_back(*found);
  }
}

void MatchSession::attach(sim::Simulation& sim) {
  sim.setOfficials(officials_.get());
  sim.addRecorder(*this);
}

BallTouchCounter::BallTouchCounter(double physics_dt)
    : gap_steps_(static_cast<uint64_t>(std::lround(0.1 / physics_dt))) {}

std::optional<world::BallTouch> BallTouchCounter::next(
    const std::optional<world::BallTouch>& last) {
  if (!last || (seen_ && last->step == seen_->step)) return std::nullopt;
  const bool fresh = !seen_ || last->robot != seen_->robot || last->step > seen_->step + gap_steps_;
  seen_ = last;
  return fresh ? last : std::nullopt;
}

void MatchSession::record(const sim::PeriodRecord& p) {
  const double dt = world_->scenario().physics.control_period;
  const engine::Vec3 ball = world_->ballState().pose.translation();
  double nearest[2] = {1e9, 1e9};
  const referee::Game& g = officials_->game();
  if (g.shootoutOpen() && g.shotKickedYet()) {
    diving_keeper_.reset();
    for (size_t i = 0; i < records_.size(); ++i)
      if (records_[i].team != g.kickingTeam() && records_[i].number == g.shootoutKeeper())
        diving_keeper_ = i;
  }
  for (world::RobotId r = 0; r < world_->robotCount(); ++r) {
    RobotRecord& rec = records_[r];
    const engine::Vec3 p = world_->torsoPose(r).translation();
    const bool standing = world_->isStanding(r);
    if (rec.standing && !standing) {
      if (diving_keeper_ == r) {
        ++rec.dives;
        diving_keeper_.reset();
      } else {
        FallRecord f;
        f.time = world_->time();
        f.x = p.x();
        f.y = p.y();
        f.ball = (p - ball).head<2>().norm();
        for (world::RobotId o = 0; o < world_->robotCount(); ++o) {
          if (o == r) continue;
          const double d = (world_->torsoPose(o).translation() - p).head<2>().norm();
          f.nearest_robot = std::min(f.nearest_robot.value_or(d), d);
        }
        rec.falls.push_back(f);
        rec.down_after_fall = true;
      }
    }
    if (!rec.standing && standing) rec.standing_since = world_->time();
    if (standing && rec.down_after_fall && world_->time() - rec.standing_since >= 1.0) {
      FallRecord& f = rec.falls.back();
      if (std::hypot(p.x() - f.x, p.y() - f.y) < 1.0) f.up_after = rec.standing_since - f.time;
      rec.down_after_fall = false;
    }
    rec.standing = standing;
    const double step = (p - rec.last).head<2>().norm();
    if (standing && step < 0.05) rec.distance += step;  // more: the referee moved it
    rec.last = p;
    const double d = (p - ball).head<2>().norm();
    nearest[rec.team] = std::min(nearest[rec.team], d);
  }
  // Possession: the team with a robot nearest the ball, within 0.5 m.
  const int team = nearest[0] <= nearest[1] ? 0 : 1;
  if (nearest[team] < 0.5) possession_[static_cast<size_t>(team)] += dt;
  // A touch by the other team's robot than the last toucher's: was the ball, just before it
  // (at the end of the period before), rolling into a goal?
  const std::optional<world::BallTouch> previous = touches_->last();
  if (const auto touch = touches_->next(world_->lastBallTouch())) {
    ++records_[touch->robot].touches;
    if (previous && world_->robot(previous->robot).team != world_->robot(touch->robot).team) {
      before_other_team_ = previous->robot;
      other_team_since_ = world_->time();
      const engine::Vec3 b = ball_before_.pose.translation();
      heading_for_goal_ = world_->field().goalReachedByRollingBall(
          b.x(), b.y(), ball_before_.linear_velocity.x(), ball_before_.linear_velocity.y());
    }
  }
  for (const sim::Event& e : *p.events) {
    if (e.type != sim::EventType::Goal) continue;
    Goal goal{world_->time(), e.team, e.player, false};
    const auto& last = touches_->last();
    if (goal.scorer == 0 && e.team >= 0 && last) {
      // The last robot to touch the ball, or the shooter whose shot it deflected.
      const world::RobotInfo& toucher = world_->robot(last->robot);
      goal.scorer = toucher.number;
      goal.own_goal = toucher.team != e.team;
      // The goal's side: where the ball was the period before (the referee has placed it since).
      const int side = ball_before_.pose.translation().x() > 0 ? 1 : -1;
      if (goal.own_goal && before_other_team_ &&
          world_->robot(*before_other_team_).team == e.team && heading_for_goal_ == side &&
          world_->time() - other_team_since_ <= kDeflectedShotSeconds) {
        goal.deflected_by = goal.scorer;
        goal.scorer = world_->robot(*before_other_team_).number;
        goal.own_goal = false;
      }
    }
    goals_.push_back(goal);
  }
  ball_before_ = world_->ballState();
}

std::array<double, 2> MatchSession::possession() const {
  const double total = possession_[0] + possession_[1];
  if (total <= 0) return {0.0, 0.0};
  return {possession_[0] / total, possession_[1] / total};
}

}  // namespace simsoccer::match
