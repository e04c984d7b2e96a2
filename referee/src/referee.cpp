#include "simsoccer/referee/referee.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "simsoccer/engine/config.hpp"

namespace simsoccer::referee {

using engine::Vec3;
using world::RobotId;

Referee::Referee(world::World& world, const RuleBook& rules, const std::array<TeamSetup, 2>& teams,
                 int kick_off_team, const RefereeConfig& config)
    : world_(world), config_(config), game_(rules, teams, kick_off_team) {
  fallen_for_.assign(world.robotCount(), 0.0);
  get_ups_.assign(world.robotCount(), GetUps{});
  idle_for_.assign(world.robotCount(), 0.0);
  idle_anchor_.assign(world.robotCount(), Vec3::Zero());
  in_goal_area_since_.assign(world.robotCount(), -1.0);
  clear_by_.assign(world.robotCount(), 0.0);
  parked_.assign(world.robotCount(), false);
  slot_.assign(world.robotCount(), -1);
  contact_for_.assign(world.robotCount() * world.robotCount(), 0.0);
  contact_gap_.assign(world.robotCount() * world.robotCount(), 1e9);
  contact_start_.assign(2 * world.robotCount() * world.robotCount(), Vec3::Zero());
  for (RobotId r = 0; r < world.robotCount(); ++r)
    arm_link_.push_back(armLinks(*world.robot(r).model));
  stuck_ball_ = world.ballState().pose.translation();
}

std::vector<char> armLinks(const robots::RobotModel& model) {
  const engine::ArticulatedModel& body = *model.body;
  const size_t n = body.links.size();
  std::vector<char> arm(n, 0);
  if (!model.hasLegs()) return arm;  // no legs named: no telling the limbs apart
  // Per link, the trunk's child it hangs from (-1: the trunk). A joint's parent
  // link comes before its child link.
  std::vector<int> limb(n, -1);
  for (const engine::Joint& j : body.joints)
    limb[static_cast<size_t>(j.child_link)] =
        j.parent_link == 0 ? j.child_link : limb[static_cast<size_t>(j.parent_link)];
  std::vector<char> arm_limb(n, 1);  // the limbs that hold neither a foot nor a camera
  const auto notAnArm = [&](int link) {
    if (link > 0 && limb[static_cast<size_t>(link)] > 0)
      arm_limb[static_cast<size_t>(limb[static_cast<size_t>(link)])] = 0;
  };
  for (const robots::LegChain& leg : model.legs) notAnArm(leg.foot_link);
  for (size_t k = 0; k < model.cameraCount(); ++k) notAnArm(model.camera(k).link);
  for (size_t l = 1; l < n; ++l) arm[l] = limb[l] > 0 && arm_limb[static_cast<size_t>(limb[l])];
  return arm;
}

std::optional<RobotId> Referee::robot(int team, int number) const {
  for (RobotId r = 0; r < world_.robotCount(); ++r)
    if (world_.robot(r).team == team && world_.robot(r).number == number) return r;
  return std::nullopt;
}

int Referee::teamSign(int team) const {
  return team == game_.leftTeam() ? -1 : 1;
}

int Referee::defenderOfSide(int side) const {
  return side < 0 ? game_.leftTeam() : 1 - game_.leftTeam();
}

world::Pose Referee::penaltySpot(int team, int index) const {
  const auto& f = world_.field();
  const double x = penaltyMarkX(teamSign(team)) + 0.35 * index * -teamSign(team);
  const double side = index % 2 == 0 ? 1.0 : -1.0;  // alternate touchlines
  world::Pose p = world::Pose::Identity();
  p.translation() = Vec3(x, side * (f.halfWidth() + 0.5), 0.0);
  p.rotate(Eigen::AngleAxisd(side > 0 ? -M_PI / 2 : M_PI / 2, Vec3::UnitZ()));  // facing the field
  return p;
}

void Referee::placeBall(double x, double y) {
  engine::RigidBodyState b;
  b.pose = engine::Pose::Identity();
  b.pose.translation() = Vec3(x, y, world_.field().ball.radius);
  world_.setBallState(b);
  stuck_ball_ = b.pose.translation();
  stuck_for_ = 0.0;
}

fields::AreaSize Referee::penaltyArea() const {
  return world_.field().penalty_area.value_or(fields::AreaSize{1.65, 4.0});  // SPL sizes
}

fields::AreaSize Referee::goalArea() const {
  return world_.field().goal_area.value_or(fields::AreaSize{0.6, 2.2});
}

double Referee::freeKickDistance() const {
  return game_.rules().free_kick_distance_centre_circle ? world_.field().centre_circle_radius
                                                        : game_.rules().free_kick_distance;
}

double Referee::depthInAvoidance(RobotId r) const {
  const int kicking = game_.kickingTeam();
  const gc::SetPlay play = game_.currentSetPlay();
  if (kicking < 0 || play == gc::SetPlay::None || play == gc::SetPlay::PenaltyKick ||
      world_.robot(r).team == kicking)
    return 0.0;
  const Vec3 p = world_.torsoPose(r).translation();
  if (play == gc::SetPlay::GoalKick && game_.rules().goal_kick_clears_penalty_area) {
    const fields::AreaSize a = penaltyArea();
    if (!inOwnArea(kicking, p, a)) return 0.0;
    const double x = teamSign(kicking) * p.x();  // towards the kicking team's goal
    return std::min(x - (world_.field().halfLength() - a.length), 0.5 * a.width - std::abs(p.y()));
  }
  return freeKickDistance() - (world_.ballState().pose.translation() - p).head<2>().norm();
}

double Referee::penaltyMarkX(int side) const {
  const auto& f = world_.field();
  return side * (f.halfLength() - f.penalty_mark_distance.value_or(1.3));
}

bool Referee::inOwnArea(int team, const Vec3& p, const fields::AreaSize& area) const {
  const auto& f = world_.field();
  const double x = teamSign(team) * p.x();  // > 0 towards the own goal
  return x >= f.halfLength() - area.length && x <= f.halfLength() + f.goal.depth &&
         std::abs(p.y()) <= 0.5 * area.width;
}

bool Referee::inOwnArea(RobotId r, const fields::AreaSize& area) const {
  return inOwnArea(world_.robot(r).team, world_.torsoPose(r).translation(), area);
}

void Referee::awardGoalKick(int defender, int side, double y) {
  game_.setPlay(gc::SetPlay::GoalKick, defender);
  const fields::AreaSize area = goalArea();
  placeBall(side * (world_.field().halfLength() - area.length),
            (y >= 0 ? 1.0 : -1.0) * 0.5 * area.width);
}

double Referee::depthInOwnGoalArea(RobotId r) const {
  const auto& f = world_.field();
  const fields::AreaSize area = goalArea();
  const Vec3 p = world_.torsoPose(r).translation();
  const double x = teamSign(world_.robot(r).team) * p.x();
  // The goal line side is not a border one leaves by: robots may stand in the goal.
  return std::min(x - (f.halfLength() - area.length), 0.5 * area.width - std::abs(p.y()));
}

bool Referee::contestingTheBall(RobotId pusher, RobotId victim, const Vec3& velocity) const {
  const auto flat = [](Vec3 v) {
    v.z() = 0.0;
    return v;
  };
  const Vec3 ball = flat(world_.ballState().pose.translation());
  const Vec3 p = flat(world_.torsoPose(pusher).translation());
  const Vec3 q = flat(world_.torsoPose(victim).translation());
  const double gap = (q - p).norm();
  if ((ball - p).norm() > config_.contest_distance || gap < 1e-6) return false;
  const Vec3 towards = (q - p) / gap;  // from the pusher to the victim
  const auto heading = [&](RobotId r) {
    return flat(world_.torsoPose(r).linear().col(0)).normalized();
  };
  const double facing = heading(pusher).dot(towards);  // cos of the victim's bearing
  const double front = std::cos(config_.contest_angle);
  // Front to front with the ball between them: each faces the other and the ball
  // lies on the stretch between them (their torsos, leaning over it, may be past it).
  const double along = (ball - p).dot(towards);
  const double across = (ball - p - along * towards).norm();
  const double reach = config_.contest_corridor;
  if (facing >= front && heading(victim).dot(-towards) >= front && along > -reach &&
      along < gap + reach && across <= reach)
    return true;
  // Side contact while going to the ball: the pusher walks towards the ball and
  // the victim is at its side, not in front of it.
  const Vec3 to_ball = ball - p;
  const Vec3 v = flat(velocity);
  const bool to_the_ball = v.dot(to_ball) >= front * v.norm() * to_ball.norm();
  return to_the_ball && std::abs(facing) < front;
}

void Referee::checkPushing() {
  const size_t n = world_.robotCount();
  const double dt = world_.scenario().physics.control_period;
  std::vector<char> touching(n * n, 0);
  for (const engine::LinkContact& c : world_.contacts()) {
    if (c.other_articulation < 0) continue;
    const size_t a = std::min<size_t>(c.articulation, static_cast<size_t>(c.other_articulation));
    const size_t b = std::max<size_t>(c.articulation, static_cast<size_t>(c.other_articulation));
    if (a == b || b >= n || world_.robot(a).team == world_.robot(b).team) continue;
    touching[a * n + b] = 1;
  }
  for (RobotId a = 0; a < n; ++a)
    for (RobotId b = a + 1; b < n; ++b) {
      const size_t k = a * n + b;
      double& t = contact_for_[k];
      if (!touching[k]) {
        // A contact episode lasts through short gaps (a shove bounces).
        contact_gap_[k] += dt;
        if (contact_gap_[k] > config_.push_gap) t = 0.0;
        if (t == 0.0) continue;
      } else {
        if (t == 0.0) {  // a new contact
          contact_start_[2 * k] = world_.torsoPose(a).translation();
          contact_start_[2 * k + 1] = world_.torsoPose(b).translation();
        }
        contact_gap_[k] = 0.0;
        t += dt;
      }
      const auto& ia = world_.robot(a);
      const auto& ib = world_.robot(b);
      if (game_.penalty(ia.team, ia.number) != gc::Penalty::None ||
          game_.penalty(ib.team, ib.number) != gc::Penalty::None)
        continue;
      // Who drives into whom: the horizontal speed towards the other.
      const Vec3 pa = world_.torsoPose(a).translation(), pb = world_.torsoPose(b).translation();
      Vec3 ab = pb - pa;
      ab.z() = 0.0;
      if (ab.norm() < 1e-6) continue;
      ab.normalize();
      const Vec3 velocity_a = world_.physics().rootLinearVelocity(ia.body);
      const Vec3 velocity_b = world_.physics().rootLinearVelocity(ib.body);
      const double va = velocity_a.dot(ab);
      const double vb = -velocity_b.dot(ab);
      const RobotId pusher = va >= vb ? a : b, victim = pusher == a ? b : a;
      const double speed = std::max(va, vb);
      const auto& ip = world_.robot(pusher);
      const auto& iv = world_.robot(victim);
      // The exceptions the rules list that a world model can see: a
      // stationary robot, one getting up, the goalkeeper in its own area.
      if (speed < config_.push_speed || !world_.isStanding(pusher)) continue;
      if (game_.goalkeeper(ip.team) == ip.number && inOwnArea(pusher, penaltyArea())) continue;
      // Contesting the ball as the rules allow: the contact so far does not count.
      if (contestingTheBall(pusher, victim, pusher == a ? velocity_a : velocity_b)) {
        t = 0.0;
        continue;
      }
      const bool fell = !world_.isStanding(victim);
      const Vec3 shoved =
          world_.torsoPose(victim).translation() - contact_start_[2 * k + (victim == a ? 0 : 1)];
      const bool displaced = shoved.dot(pusher == a ? ab : Vec3(-ab)) >= config_.push_displacement;
      if (t < config_.push_time && !fell && !displaced) continue;
      t = 0.0;
      contact_gap_[k] = 1e9;
      game_.penalise(ip.team, ip.number, gc::Penalty::PlayerPushing);
      game_.recordEvent(EventType::Pushing, ip.team, ip.number,
                        "pushed team " + std::to_string(iv.team) + " player " +
                            std::to_string(iv.number) + (fell ? " over" : ""));
      // Near the ball in open play: a foul, the other team gets a free kick
      // (a penalty kick when it happened in the pusher's own penalty area).
      const Vec3 ball = world_.ballState().pose.translation();
      if (game_.state() == gc::State::Playing && game_.kickingTeam() < 0 &&
          (ball - (pusher == a ? pa : pb)).head<2>().norm() <= config_.foul_ball_distance) {
        // A penalty kick when the pushed robot is in the pusher's own penalty area.
        const bool in_area =
            inOwnArea(ip.team, world_.torsoPose(victim).translation(), penaltyArea());
        game_.setPlay(in_area ? gc::SetPlay::PenaltyKick : gc::SetPlay::PushingFreeKick, iv.team);
        // The ball stays where it is; one still rolling (kicked just before the call) is stopped
        // there. Left rolling, a K1's kick just before the call carried it 6 m on to two
        // opponents, who were called too close to it while the kicking team's touch, before the
        // award, could not end the free kick (K1 5 v 5 seed 57).
        if (!in_area &&
            world_.ballState().linear_velocity.head<2>().norm() >= config_.ball_stopped_speed)
          placeBall(ball.x(), ball.y());
        set_play_ball_ = ball;
        set_play_step_ = world_.stepCount();
      }
    }
}

void Referee::checkArmContact() {
  // Playing with arms: a standing field player (or the goalkeeper outside its
  // penalty area) touching the ball with an arm. The ball goes back to where
  // it was touched.
  const auto touch = world_.lastBallTouch();
  if (!touch || touch->step <= arm_checked_step_) return;
  arm_checked_step_ = touch->step;
  const RobotId r = touch->robot;
  const auto& arm = arm_link_[r];
  if (touch->link < 0 || static_cast<size_t>(touch->link) >= arm.size() ||
      !arm[static_cast<size_t>(touch->link)])
    return;
  const auto& info = world_.robot(r);
  if (game_.penalty(info.team, info.number) != gc::Penalty::None || !world_.isStanding(r)) return;
  if (game_.goalkeeper(info.team) == info.number && inOwnArea(r, penaltyArea())) return;
  game_.penalise(info.team, info.number, gc::Penalty::IllegalBallContact);
  game_.recordEvent(EventType::BallContact, info.team, info.number, "played the ball with an arm");
  const Vec3 p = world_.ballState().pose.translation();
  placeBall(p.x(), p.y());
}

std::vector<char> Referee::legalPositions() const {
  const auto& f = world_.field();
  const size_t n = world_.robotCount();
  std::vector<char> legal(n, 1);
  const int kicking = game_.kickingTeam();
  const bool penalty_kick = game_.currentSetPlay() == gc::SetPlay::PenaltyKick;
  // A followed GameController that hides the kicking side (kickingTeam 255, the Champions
  // Cup, without its true data): which penalty area is whose is not known here.
  if (penalty_kick && kicking < 0) return legal;
  // The one kicking-team robot allowed in the centre circle (kick-off) or
  // in the penalty area (penalty kick): the one nearest the ball's spot.
  const Vec3 spot = penalty_kick ? Vec3(penaltyMarkX(-teamSign(kicking)), 0.0, 0.0) : Vec3::Zero();
  std::optional<RobotId> taker;
  for (RobotId r = 0; r < n; ++r) {
    const auto& info = world_.robot(r);
    if (info.team != kicking || game_.penalty(info.team, info.number) != gc::Penalty::None)
      continue;
    const double d = (world_.torsoPose(r).translation() - spot).head<2>().norm();
    if (!taker || d < (world_.torsoPose(*taker).translation() - spot).head<2>().norm()) taker = r;
  }
  for (RobotId r = 0; r < n; ++r) {
    const auto& info = world_.robot(r);
    if (game_.penalty(info.team, info.number) != gc::Penalty::None) continue;
    const Vec3 p = world_.torsoPose(r).translation();
    const double own = teamSign(info.team) * p.x();  // > 0 in the own half
    // On the field, or inside the own goal (not elsewhere on the border strip).
    const bool in_own_goal = own > f.halfLength() && own <= f.halfLength() + f.goal.depth &&
                             std::abs(p.y()) < 0.5 * f.goal.inner_width;
    const bool on_field =
        (std::abs(p.x()) <= f.halfLength() && std::abs(p.y()) <= f.halfWidth()) || in_own_goal;
    if (!on_field) {
      legal[r] = 0;
      continue;
    }
    if (penalty_kick) {
      // Only the defending goalkeeper and the taker inside the defending team's penalty area.
      const int defender = 1 - kicking;
      const bool in_area = inOwnArea(defender, p, penaltyArea());
      const bool keeper = info.team == defender && game_.goalkeeper(defender) == info.number;
      legal[r] = !in_area || keeper || (taker && r == *taker);
      continue;
    }
    const bool in_circle = std::hypot(p.x(), p.y()) <= f.centre_circle_radius;
    if (info.team == kicking)
      legal[r] = own > 0.0 || (in_circle && taker && r == *taker);
    else
      legal[r] =
          own > 0.0 && !in_circle;  // defenders (and drop balls): own half, outside the circle
  }
  return legal;
}

Vec3 Referee::nearestLegalPosition(RobotId r, const std::vector<Vec3>& taken) const {
  const auto& f = world_.field();
  const int team = world_.robot(r).team;
  const double s = teamSign(team);
  Vec3 p = world_.torsoPose(r).translation();
  p.z() = 0.0;
  p.x() = std::clamp(p.x(), -f.halfLength() + 0.3, f.halfLength() - 0.3);
  p.y() = std::clamp(p.y(), -f.halfWidth() + 0.3, f.halfWidth() - 0.3);
  if (game_.currentSetPlay() == gc::SetPlay::PenaltyKick) {
    // Out of the defending team's penalty area, straight back towards the field.
    const int defender = 1 - game_.kickingTeam();
    const fields::AreaSize area = penaltyArea();
    const double edge = f.halfLength() - area.length - 0.3;
    if (teamSign(defender) * p.x() > edge && std::abs(p.y()) < 0.5 * area.width + 0.3)
      p.x() = teamSign(defender) * edge;
  } else {
    if (s * p.x() < 0.3) p.x() = s * 0.3;  // into the own half
    const double clear = f.centre_circle_radius + 0.3;
    if (p.head<2>().norm() < clear) {  // out of the circle, radially
      Vec3 dir = p.head<2>().norm() > 1e-6 ? Vec3(p.x(), p.y(), 0.0).normalized() : Vec3(s, 0, 0);
      p = clear * dir;
    }
  }
  // Not onto a robot placed before it: step sideways.
  for (int i = 0; i < 20; ++i) {
    bool clash = false;
    for (const Vec3& q : taken) clash = clash || (q - p).head<2>().norm() < 0.4;
    if (!clash) break;
    p.y() += (p.y() <= 0 ? 0.4 : -0.4) * (i % 2 == 0 ? 1 : -1) * (i / 2 + 1);
    p.y() = std::clamp(p.y(), -f.halfWidth() + 0.3, f.halfWidth() - 0.3);
  }
  return p;
}

void Referee::onEnterSet() {
  if (game_.phase() == gc::GamePhase::PenaltyShoot) return;  // placed by startShootoutKick
  // The ball goes to the centre mark for a kick-off or drop ball, to the
  // penalty mark for a penalty kick.
  if (game_.currentSetPlay() != gc::SetPlay::PenaltyKick)
    placeBall(0.0, 0.0);
  else if (game_.kickingTeam() >= 0)  // (hidden by a followed GameController: left where it is)
    placeBall(penaltyMarkX(-teamSign(game_.kickingTeam())), 0.0);
  // Illegal positions: penalised (15 s), or moved by auto-placement to the
  // nearest legal spot.
  const std::vector<char> legal = legalPositions();
  std::vector<Vec3> taken;
  for (RobotId r = 0; r < world_.robotCount(); ++r)
    if (legal[r]) taken.push_back(world_.torsoPose(r).translation());
  for (RobotId r = 0; r < world_.robotCount(); ++r) {
    if (legal[r]) continue;
    const auto& info = world_.robot(r);
    if (config_.auto_placement) {
      const Vec3 p = nearestLegalPosition(r, taken);
      taken.push_back(p);
      world_.moveRobot(r, p.x(), p.y(), teamSign(info.team) < 0 ? 0.0 : M_PI);
      game_.recordEvent(EventType::Placement, info.team, info.number, "auto-placed to a legal position");
    } else {
      game_.penalise(info.team, info.number, gc::Penalty::IllegalPositionInSet);
    }
  }
}

bool Referee::getUpsFailed(RobotId r, bool standing) {
  GetUps& g = get_ups_[r];
  if (standing && !g.was_standing) g.stood_up_at = clock_;
  if (!standing && g.was_standing) {  // down again
    if (clock_ - g.stood_up_at < config_.get_up_hold_time) {
      ++g.failed;
      const Vec3 p = world_.torsoPose(r).translation();
      for (RobotId o = 0; o < world_.robotCount(); ++o)
        if (o != r && (world_.torsoPose(o).translation() - p).head<2>().norm() <
                          config_.get_up_disturbed_distance)
          g.disturbed = true;
    } else {
      g.failed = 0;  // a fall from standing, not a failed get-up
      g.disturbed = false;
    }
  }
  g.was_standing = standing;
  return g.failed >= game_.rules().get_up_attempts + (g.disturbed ? 1 : 0);
}

// The teams' handlers put their robots in their own halves before a half's
// kick-off (the rules: on the touchlines of the own half). For the second
// half, each robot in play goes to its start pose from the scenario turned
// with the sides (x, y and the heading turned half a turn about the centre
// mark): otherwise both teams, wherever the first half ended, walked through
// each other to their new halves in Ready, and pushed. They take them as the
// break begins (enterState): left where the half ended until the second half's
// Initial, a K1 down in a crowd before a goal got up again and again into its
// neighbours and knocked them over (7 falls in one break of a 5 v 5 game).
void Referee::placeForTheSecondHalf() {
  placed_for_second_half_ = true;
  for (RobotId r = 0; r < world_.robotCount(); ++r) {
    const auto& info = world_.robot(r);
    if (game_.penalty(info.team, info.number) == gc::Penalty::Substitute) continue;
    const world::RobotPlacement& start = world_.scenario().robots.at(r);
    world_.moveRobot(r, -start.x, -start.y, start.yaw + M_PI);
    game_.recordEvent(EventType::Placement, info.team, info.number,
                      "placed in its half for the second half");
  }
}

int ballInGoal(const fields::FieldModel& f, const Vec3& p) {
  if (std::abs(p.x()) <= f.halfLength() + 0.5 * f.line_width + f.ball.radius) return 0;
  if (std::abs(p.y()) >= 0.5 * f.goal.inner_width || p.z() >= f.goal.clear_height) return 0;
  return p.x() > 0 ? 1 : -1;
}

void Referee::checkBall() {
  const auto& f = world_.field();
  const engine::RigidBodyState b = world_.ballState();
  const Vec3 p = b.pose.translation();
  const double r = f.ball.radius;
  const double line = 0.5 * f.line_width;
  const auto touch = world_.lastBallTouch();
  const int last_team = touch ? world_.robot(touch->robot).team : -1;

  if (std::abs(p.x()) > f.halfLength() + line + r) {
    const int side = p.x() > 0 ? 1 : -1;
    const int defender = defenderOfSide(side);
    const int attacker = 1 - defender;
    if (ballInGoal(f, p) == side) {
      // A goal straight from a restart the rule book calls indirect becomes a goal kick; a
      // free kick straight into the kicker's own goal a corner kick (HSL).
      const bool own_goal = last_team == defender;
      const std::string refused = directGoalRefused(attacker, own_goal);
      if (!refused.empty()) {
        game_.recordEvent(EventType::GoalDisallowed, attacker, 0, refused);
        awardGoalKick(defender, side, p.y());
      } else if (own_goal && ownGoalFromFreeKick(defender)) {
        game_.recordEvent(EventType::GoalDisallowed, attacker, 0,
                          "own goal straight from a free kick: corner kick");
        game_.setPlay(gc::SetPlay::CornerKick, attacker);
        placeBall(side * f.halfLength(), (p.y() >= 0 ? 1.0 : -1.0) * f.halfWidth());
      } else {
        game_.goal(attacker);  // a goal for the team attacking this goal (own goals too)
        placeBall(0.0, 0.0);
        return;
      }
    } else if (last_team == attacker || last_team < 0) {
      awardGoalKick(defender, side, p.y());  // over the goal line, last touched by the attackers
    } else {
      game_.setPlay(gc::SetPlay::CornerKick, attacker);
      placeBall(side * f.halfLength(), (p.y() >= 0 ? 1.0 : -1.0) * f.halfWidth());
    }
  } else if (std::abs(p.y()) > f.halfWidth() + line + r) {
    // Over a touchline: kick-in for the team that did not touch it last.
    const int team =
        last_team >= 0 ? 1 - last_team : (p.x() < 0 ? game_.leftTeam() : 1 - game_.leftTeam());
    game_.setPlay(gc::SetPlay::KickIn, team);
    placeBall(std::clamp(p.x(), -f.halfLength(), f.halfLength()),
              (p.y() > 0 ? 1.0 : -1.0) * f.halfWidth());
  } else {
    return;
  }
  set_play_ball_ = world_.ballState().pose.translation();
  set_play_step_ = world_.stepCount();
}

std::string Referee::directGoalRefused(int attacker, bool own_goal) const {
  if (own_goal) return {};  // own goals always count (but see ownGoalFromFreeKick)
  const RuleBook& rules = game_.rules();
  const size_t a = static_cast<size_t>(attacker);
  const int robots_touched = std::popcount(touched_since_restart_[0] | touched_since_restart_[1]);
  // The SPL (2025): after any restart but a penalty kick (a saved one, touched by another
  // robot, is a failed penalty kick: the rule holds again), two robots of the scoring team.
  const bool penalty_kick = restart_.play == gc::SetPlay::PenaltyKick && robots_touched <= 1;
  if (rules.indirect_kick && std::popcount(touched_since_restart_[a]) < 2 && !penalty_kick)
    return "indirect kick: fewer than two of its robots played the ball";
  if (restart_.team != attacker) return {};
  // The HSL: not straight from the kick-off ...
  if (restart_.kickOff() && !rules.kick_off_direct_goal) {
    if (restart_.robots >= 3 && robots_touched < 2)
      return "kick-off: two different robots must touch the ball before a goal";
    if (restart_.robots < 3 && !restart_.kicker_outside_circle && robots_touched < 2)
      return "kick-off: its kicker must touch the ball outside the centre circle before a goal";
  }
  // ... nor straight from a kick-in: another robot, of either team, must touch it.
  if (restart_.play == gc::SetPlay::KickIn && rules.kick_in_indirect && robots_touched < 2)
    return "kick-in: another robot must touch the ball before a goal";
  return {};
}

bool Referee::ownGoalFromFreeKick(int defender) const {
  // Straight in: the team that took the free kick scores into its own goal, its kicker the
  // only robot that touched the ball since.
  if (!game_.rules().free_kick_own_goal_corner || restart_.team != defender ||
      restart_.play == gc::SetPlay::None || restart_.play == gc::SetPlay::PenaltyKick)
    return false;
  return std::popcount(touched_since_restart_[0] | touched_since_restart_[1]) == 1 &&
         touched_since_restart_[static_cast<size_t>(defender)] != 0;
}

void Referee::beginRestart() {
  touched_since_restart_ = {0, 0};
  restart_ = Restart{};
  restart_.play = game_.currentSetPlay();
  restart_.team = game_.kickingTeam();
  if (restart_.team < 0) return;
  for (RobotId r = 0; r < world_.robotCount(); ++r) {
    const auto& info = world_.robot(r);
    restart_.robots +=
        info.team == restart_.team && game_.penalty(info.team, info.number) == gc::Penalty::None;
  }
}

void Referee::noteRestartTouch(RobotId r) {
  const int team = world_.robot(r).team;
  if (r < 64) touched_since_restart_[static_cast<size_t>(team)] |= uint64_t{1} << r;
  if (team != restart_.team) return;
  if (restart_.kicker < 0) restart_.kicker = static_cast<int>(r);
  if (restart_.kicker == static_cast<int>(r) &&
      world_.ballState().pose.translation().head<2>().norm() > world_.field().centre_circle_radius)
    restart_.kicker_outside_circle = true;
}

void Referee::checkSetPlayOver() {
  // A kick-off or set play ends when the kicking team touches the ball and moves it clearly.
  const int kicking = game_.kickingTeam();
  if (kicking < 0) return;
  const auto touch = world_.lastBallTouch();
  if (!touch || touch->step <= set_play_step_ || world_.robot(touch->robot).team != kicking) return;
  const Vec3 p = world_.ballState().pose.translation();
  if ((p - set_play_ball_).head<2>().norm() >= config_.ball_moved) game_.ballFree();
}

void Referee::checkPenalties() {
  const auto& f = world_.field();
  const double dt = world_.scenario().physics.control_period;
  const bool in_game = game_.state() == gc::State::Ready || game_.state() == gc::State::Set ||
                       game_.state() == gc::State::Playing;
  std::array<std::vector<RobotId>, 2> in_goal_area;
  for (RobotId r = 0; r < world_.robotCount(); ++r) {
    const auto& info = world_.robot(r);
    // Out of play, or placed by hand: its get-ups start over.
    if (game_.penalty(info.team, info.number) != gc::Penalty::None || !in_game) {
      get_ups_[r] = GetUps{};
      continue;
    }
    const Vec3 p = world_.torsoPose(r).translation();
    // Leaving the field: off the carpet.
    if (!f.onCarpet(p.x(), p.y())) {
      game_.penalise(info.team, info.number, gc::Penalty::LeavingTheField);
      continue;
    }
    // Fallen / inactive: down for longer than the rule's time, or its get-ups failed.
    const bool standing = world_.isStanding(r);
    fallen_for_[r] = standing ? 0.0 : fallen_for_[r] + dt;
    if (fallen_for_[r] >= game_.rules().fallen_time) {
      game_.recordEvent(EventType::Inactive, info.team, info.number,
                        "down for " + engine::formatNumber(game_.rules().fallen_time) + " s");
      game_.penalise(info.team, info.number, gc::Penalty::InactivePlayer);
      fallen_for_[r] = 0.0;
      continue;
    }
    if (getUpsFailed(r, standing)) {
      game_.recordEvent(EventType::Inactive, info.team, info.number,
                        "failed to get up " + std::to_string(get_ups_[r].failed) + " times" +
                            (get_ups_[r].disturbed ? " (disturbed)" : ""));
      game_.penalise(info.team, info.number, gc::Penalty::InactivePlayer);
      fallen_for_[r] = 0.0;
      continue;
    }
    // Illegal position before the ball is in play: the defending team
    // entering the centre circle or the other half at a kick-off, or coming
    // within the free-kick distance of the ball at a free kick.
    const Vec3 ball = world_.ballState().pose.translation();
    const int kicking = game_.kickingTeam();
    if (game_.state() == gc::State::Playing && kicking >= 0 && info.team != kicking) {
      const gc::SetPlay play = game_.currentSetPlay();
      bool illegal = false;
      if (play == gc::SetPlay::None)  // kick-off
        illegal =
            teamSign(info.team) * p.x() < 0.0 || std::hypot(p.x(), p.y()) < f.centre_circle_radius;
      else if (play != gc::SetPlay::PenaltyKick)
        illegal = clock_ >= clear_by_[r] && depthInAvoidance(r) > 0.0;
      if (illegal) {
        game_.penalise(info.team, info.number, gc::Penalty::IllegalPosition);
        game_.recordEvent(
            EventType::IllegalPosition, info.team, info.number,
            play == gc::SetPlay::None ? "entered at the opponents' kick-off"
            : play == gc::SetPlay::GoalKick && game_.rules().goal_kick_clears_penalty_area
                ? "in the penalty area at the opponents' goal kick"
                : "too close to the ball at a free kick");
        continue;
      }
    }
    // Inactive: standing without moving while the ball is near (Playing only).
    if (game_.state() != gc::State::Playing || !world_.isStanding(r) ||
        (ball - p).head<2>().norm() > config_.inactive_ball_distance ||
        (p - idle_anchor_[r]).head<2>().norm() > config_.inactive_motion) {
      idle_anchor_[r] = p;
      idle_for_[r] = 0.0;
    } else if ((idle_for_[r] += dt) >= config_.inactive_time) {
      game_.penalise(info.team, info.number, gc::Penalty::InactivePlayer);
      game_.recordEvent(EventType::Inactive, info.team, info.number, "stood idle next to the ball");
      idle_for_[r] = 0.0;
      continue;
    }
    if (inOwnArea(r, goalArea())) {
      if (in_goal_area_since_[r] < 0.0) in_goal_area_since_[r] = clock_;
      in_goal_area[static_cast<size_t>(info.team)].push_back(r);
    } else {
      in_goal_area_since_[r] = -1.0;
    }
  }
  // Goal-area limit (Set and Playing): the surplus robots, deepest first.
  if (game_.state() == gc::State::Set || game_.state() == gc::State::Playing) {
    const size_t max = static_cast<size_t>(game_.rules().goal_area_max_robots);
    for (int team = 0; team < 2; ++team) {
      auto& list = in_goal_area[static_cast<size_t>(team)];
      if (list.size() <= max) continue;
      // Who stays: in Set the robots deepest inside (the surplus closest to the
      // border is penalised); in Playing the ones that were there first.
      const bool playing = game_.state() == gc::State::Playing;
      std::sort(list.begin(), list.end(), [&](RobotId a, RobotId b) {
        if (playing && in_goal_area_since_[a] != in_goal_area_since_[b])
          return in_goal_area_since_[a] < in_goal_area_since_[b];
        const double da = depthInOwnGoalArea(a), db = depthInOwnGoalArea(b);
        return da != db ? da > db : a < b;
      });
      for (size_t i = max; i < list.size(); ++i)
        game_.penalise(team, world_.robot(list[i]).number,
                       playing ? gc::Penalty::IllegalPosition : gc::Penalty::IllegalPositionInSet);
    }
  }
}

void Referee::checkGameStuck() {
  const double dt = world_.scenario().physics.control_period;
  const Vec3 p = world_.ballState().pose.translation();
  if (game_.kickingTeam() >= 0) {
    // A kick-off or set play runs on its own timer.
    stuck_ball_ = p;
    stuck_for_ = 0.0;
    return;
  }
  if ((p - stuck_ball_).head<2>().norm() > config_.stuck_progress) {
    stuck_ball_ = p;
    stuck_for_ = 0.0;
    return;
  }
  stuck_for_ += dt;
  if (stuck_for_ < game_.rules().game_stuck_duration) return;
  stuck_for_ = 0.0;
  stuck_ball_ = p;
  // Local: the robot closest to the ball, if one is close; otherwise global: drop ball.
  std::optional<RobotId> closest;
  double best = config_.stuck_radius;
  for (RobotId r = 0; r < world_.robotCount(); ++r) {
    const auto& info = world_.robot(r);
    if (game_.penalty(info.team, info.number) != gc::Penalty::None) continue;
    const double d = (world_.torsoPose(r).translation() - p).head<2>().norm();
    if (d < best) {
      best = d;
      closest = r;
    }
  }
  if (closest)
    game_.penalise(world_.robot(*closest).team, world_.robot(*closest).number,
                   gc::Penalty::LocalGameStuck);
  else
    game_.dropBall();
}

void Referee::removePenalised() {
  for (RobotId r = 0; r < world_.robotCount(); ++r) {
    const auto& info = world_.robot(r);
    const gc::Penalty pen = game_.penalty(info.team, info.number);
    // Motion in Set is served in place where the rule book says so (the SPL's 2025 rules: the
    // robot stays where it moved, and the penalty may be revoked while still in Set; the HSL
    // removes it); the others leave.
    const bool out = pen != gc::Penalty::None && !(pen == gc::Penalty::IllegalMotionInSet &&
                                                   game_.rules().motion_in_set_in_place);
    if (out) {
      if (slot_[r] < 0) {
        // The first free waiting spot of its team; it keeps it while it waits.
        int s = 0;
        for (bool taken = true; taken; s += taken ? 1 : 0) {
          taken = false;
          for (RobotId o = 0; o < world_.robotCount(); ++o)
            taken = taken || (o != r && world_.robot(o).team == info.team && slot_[o] == s);
        }
        slot_[r] = s;
      }
      const world::Pose spot = penaltySpot(info.team, slot_[r]);
      const double yaw = std::atan2(spot.linear()(1, 0), spot.linear()(0, 0));
      // Removed at once, and kept there (re-placed if it wanders off).
      if (!parked_[r] ||
          (world_.torsoPose(r).translation() - spot.translation()).head<2>().norm() > 0.5) {
        world_.moveRobot(r, spot.translation().x(), spot.translation().y(), yaw);
        parked_[r] = true;
      }
    } else if (parked_[r]) {
      // Re-entry: on the touchline beside its waiting spot, facing the field.
      const world::Pose spot = world_.torsoPose(r);
      const double side = spot.translation().y() > 0 ? 1.0 : -1.0;
      world_.moveRobot(r, spot.translation().x(), side * world_.field().halfWidth(),
                       side > 0 ? -M_PI / 2 : M_PI / 2);
      parked_[r] = false;
    }
    if (!out) slot_[r] = -1;
  }
}

void Referee::startShootoutKick(int striker, int keeper) {
  game_.shootoutKick(striker, keeper);
  const auto& f = world_.field();
  const double side = config_.shootout_goal_side >= 0 ? 1.0 : -1.0;
  const double mark = penaltyMarkX(static_cast<int>(side));
  placeBall(mark, 0.0);
  const int team = game_.kickingTeam();
  if (const auto r = robot(team, striker)) {
    world_.moveRobot(*r, mark - side * 0.35, 0.0, side > 0 ? 0.0 : M_PI);
    parked_[*r] = false;
  }
  if (keeper > 0) {
    if (const auto r = robot(1 - team, keeper)) {
      world_.moveRobot(*r, side * (f.halfLength() - 0.05), 0.0, side > 0 ? M_PI : 0.0);
      parked_[*r] = false;
    }
  }
  removePenalised();  // the substitutes leave at once
  shot_seen_touch_step_ = world_.stepCount();
  striker_touched_ = keeper_touched_ = hit_post_ = false;
  ball_still_for_ = 0.0;
}

void Referee::checkShot() {
  const auto& f = world_.field();
  const double side = config_.shootout_goal_side >= 0 ? 1.0 : -1.0;
  const double dt = world_.scenario().physics.control_period;
  const int kicking = game_.kickingTeam();
  const auto striker = robot(kicking, game_.shootoutStriker());
  const auto keeper =
      game_.shootoutKeeper() > 0 ? robot(1 - kicking, game_.shootoutKeeper()) : std::nullopt;
  const engine::RigidBodyState b = world_.ballState();
  const Vec3 p = b.pose.translation();
  const double r = f.ball.radius;
  const double x = side * p.x();  // towards the goal

  // Who touched the ball since the last look.
  const auto touch = world_.lastBallTouch();
  if (touch && touch->step > shot_seen_touch_step_) {
    shot_seen_touch_step_ = touch->step;
    if (striker && touch->robot == *striker) {
      if (!striker_touched_) {
        striker_touched_ = true;
        first_touch_ball_ = p;
        game_.shotKicked();
      } else if ((p - first_touch_ball_).head<2>().norm() > config_.ball_replayed) {
        game_.recordEvent(EventType::Shot, kicking, game_.shootoutStriker(),
                          "striker played the ball again");
        return game_.finishShot(keeper_touched_ ? ShotOutcome::Saved : ShotOutcome::Other);
      }
    } else if (keeper && touch->robot == *keeper && striker_touched_) {
      keeper_touched_ = true;
    }
  }

  // The keeper touches the goal line and stays on its feet until the kick.
  if (keeper && !striker_touched_) {
    const double from_line =
        std::abs(side * f.halfLength() - world_.torsoPose(*keeper).translation().x());
    if (!world_.isStanding(*keeper) || from_line > config_.keeper_line_tolerance) {
      game_.recordEvent(EventType::Shot, 1 - kicking, game_.shootoutKeeper(),
                        "keeper left the goal line or fell before the kick: goal awarded");
      game_.goal(kicking);
      return;
    }
  }

  // A goal: the whole ball over the line between the posts, under the bar.
  const double line = 0.5 * f.line_width;
  if (x > f.halfLength() + line + r) {
    if (ballInGoal(f, p) == side) {
      game_.goal(kicking);
      return;
    }
  }
  // Off a post: the ball came within touching distance of one.
  const double post_r = 0.5 * f.goal.post_diameter;
  for (double py : {-1.0, 1.0}) {
    const Vec3 post(side * f.halfLength(), py * f.postCentreY(), 0.0);
    if ((p - post).head<2>().norm() <= r + post_r + 0.005) hit_post_ = true;
  }
  if (!striker_touched_) return;  // the shot clock ends a kick that never comes

  const auto outcome = [&] {
    if (keeper_touched_) return ShotOutcome::Saved;
    if (hit_post_) return ShotOutcome::Post;
    if (x > f.halfLength() + line + r) return ShotOutcome::Wide;
    return ShotOutcome::Other;
  };
  // Out of the penalty area (over the goal line, or back into the field).
  const fields::AreaSize area = penaltyArea();
  if (x > f.halfLength() + line + r || x < f.halfLength() - area.length - r ||
      std::abs(p.y()) > 0.5 * area.width + r) {
    game_.recordEvent(EventType::Shot, kicking, game_.shootoutStriker(), "ball left the penalty area");
    return game_.finishShot(outcome());
  }
  // The ball came to a stop after the striker's touch.
  ball_still_for_ =
      b.linear_velocity.head<2>().norm() < config_.ball_stopped_speed ? ball_still_for_ + dt : 0.0;
  if (ball_still_for_ >= config_.ball_stopped_time) {
    game_.recordEvent(EventType::Shot, kicking, game_.shootoutStriker(), "ball stopped");
    return game_.finishShot(outcome());
  }
}

// Whatever changed the state (the game's own timers, a command, this
// referee's whistle), the referee's bookkeeping for the new state starts here.
void Referee::enterState(gc::State s) {
  time_in_state_ = 0.0;
  still_for_ = 0.0;
  last_state_ = s;
  if (s == gc::State::Set) onEnterSet();
  const bool normal = game_.phase() != gc::GamePhase::PenaltyShoot;
  const bool break_begins =
      s == gc::State::Finished && game_.half() == Half::First && game_.rules().halves == 2;
  // (An external GameController may also go from the first half straight to the second's Initial.)
  const bool second_half_begins = s == gc::State::Initial && game_.half() == Half::Second;
  if (normal && !placed_for_second_half_ && (break_begins || second_half_begins))
    placeForTheSecondHalf();
  if (s == gc::State::Playing) {
    beginRestart();  // a kick-off, a dropped ball or a penalty kick
    restart_seen_touch_step_ = world_.stepCount();
    set_play_ball_ = world_.ballState().pose.translation();
    set_play_step_ = world_.stepCount();
    stuck_ball_ = set_play_ball_;
    stuck_for_ = 0.0;
  }
}

void Referee::follow(const ControlData& packet) {
  game_.follow(packet);
  following_ = true;
}

void Referee::update() {
  const double dt = world_.scenario().physics.control_period;
  if (!following_) {
    judge(dt);
    removePenalised();
    return;
  }
  // The external GameController's game is the truth; the automatic referee
  // judges a copy of it, and its calls are reported only.
  Game truth = game_;
  truth.followTime(dt);
  const size_t seen = game_.events().size();
  judge(dt);
  std::vector<RefereeEvent> calls(game_.events().begin() + static_cast<long>(seen),
                                  game_.events().end());
  game_ = std::move(truth);
  // The referee's memory of the state follows the truth, not its copy (else
  // a whistle the GameController has not made would enter Set again every
  // period: ball and robots re-placed).
  if (last_state_ != game_.state()) last_state_ = game_.state();
  // A call the referee keeps making (the GameController has not followed it)
  // is reported when it is first made, not every period.
  std::vector<std::string> made;
  for (const RefereeEvent& e : calls) {
    made.push_back(std::to_string(e.team) + " " + std::to_string(e.player) + " " +
                   eventName(e.type) + (e.detail.empty() ? "" : ": " + e.detail));
    if (std::find(advised_.begin(), advised_.end(), made.back()) == advised_.end())
      game_.recordEvent(EventType::Advisory, e.team, e.player,
                        std::string(eventName(e.type)) + (e.detail.empty() ? "" : ": " + e.detail));
  }
  advised_ = std::move(made);
  removePenalised();
}

void Referee::judge(double dt) {
  game_.advance(dt);
  clock_ += dt;
  if (game_.setPlaysAwarded() != last_set_play_award_ &&
      game_.currentSetPlay() != gc::SetPlay::None) {
    beginRestart();  // a free kick (or a penalty kick's award)
    for (RobotId r = 0; r < world_.robotCount(); ++r)
      clear_by_[r] = clock_ + config_.free_kick_clear_time +
                     std::max(0.0, depthInAvoidance(r)) / config_.leave_speed;
  }
  last_set_play_award_ = game_.setPlaysAwarded();
  // A kick-off or free kick the kicking team never took (its time ran out): no goal comes
  // straight from it.
  if (restart_.team >= 0 && restart_.kicker < 0 && game_.kickingTeam() < 0 &&
      game_.state() == gc::State::Playing)
    restart_ = Restart{};
  const gc::State s = game_.state();
  if (s != last_state_)
    enterState(s);
  else
    time_in_state_ += dt;

  if (game_.phase() == gc::GamePhase::PenaltyShoot) {
    if (game_.shootoutOpen() && s == gc::State::Set && config_.set_duration > 0 &&
        time_in_state_ >= config_.set_duration) {
      game_.playing();  // the whistle
      enterState(game_.state());
    } else if (game_.shootoutOpen() && s == gc::State::Playing) {
      checkShot();
    }
  } else if (!game_.gameOver()) {
    checkPenalties();
    if (s == gc::State::Ready || s == gc::State::Set || s == gc::State::Playing) checkPushing();
    if (s == gc::State::Ready) {
      // Ready ends early when every robot in play stands still in a legal place.
      bool all = true;
      const std::vector<char> legal = legalPositions();
      for (RobotId r = 0; r < world_.robotCount() && all; ++r) {
        const auto& info = world_.robot(r);
        if (game_.penalty(info.team, info.number) != gc::Penalty::None) continue;
        all = legal[r] && world_.isStanding(r) &&
              world_.physics().rootLinearVelocity(world_.robot(r).body).head<2>().norm() <
                  config_.still_speed;
      }
      still_for_ = all ? still_for_ + dt : 0.0;
      if (all && still_for_ >= config_.ready_still_time) game_.set();
    } else if (s == gc::State::Set && config_.set_duration > 0 &&
               time_in_state_ >= config_.set_duration) {
      game_.playing();  // the whistle
      enterState(game_.state());
    } else if (s == gc::State::Playing) {
      if (const auto t = world_.lastBallTouch(); t && t->step > restart_seen_touch_step_) {
        restart_seen_touch_step_ = t->step;
        noteRestartTouch(t->robot);
      }
      checkArmContact();
      checkBall();
      checkSetPlayOver();
      if (game_.state() == gc::State::Playing) checkGameStuck();
    }
  }
}

}  // namespace simsoccer::referee
