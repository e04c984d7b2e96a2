#!/usr/bin/env python3
"""Cross-entropy search over a robot's walk parameters (the `walk:` part of its gait.yaml),
each candidate scored in the simulator by `simsoccer bench motion --robot ROBOT --vx ...`
walks (one robot, the walk engine alone, the same period pipeline as a match). How
configs/motions/booster_k1/gait.yaml was found: its header says with which settings.

  python3 scripts/tune_gait.py ROBOT OUTDIR [generations] [population]

ROBOT: a robot with a motion bench (configs/bench/motion_ROBOT.yaml). The search starts
from the robot's gait file (its walk parameters; unnamed ones from the code's defaults)
and writes OUTDIR/gait.yaml (the best candidate so far, its kick part copied) each
generation. A candidate walks each command of WALKS (vx vy turn seconds): score per walk
0.5 + 1.5 achieved/commanded speed (capped at 1; on the spot: 1 - metres moved) - drift
(sideways per metre walked, turn in half turns) when it stays up, else half the share of
the walk it stood. The mean over the walks.
Defaults: 30 generations of 16 candidates. Environment:
  WALKS="0.5 0 0 12;0 0 0 6"   the commands (default: forward at the bench's target,
                               half of it, on the spot, back, sideways, turning)
  SIGMA=S      the initial spread, a share of each parameter's range (default 0.25)
  SIM=PATH     the simsoccer binary (default build/apps/simsoccer)
Needs python3-yaml; runs two walks at a time."""
import concurrent.futures as cf
import math
import os
import random
import re
import subprocess
import sys

import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIM = os.environ.get("SIM", os.path.join(ROOT, "build/apps/simsoccer"))
# The parameters searched, with their ranges: name, bench knob, lowest, highest.
SPACE = [
    ("step_period", "period", 0.22, 0.45),
    ("foot_lift", "lift", 0.01, 0.09),
    ("ankle_height", "height", 0.40, 0.49),
    ("sway", "sway", 0.0, 0.06),
    ("torso_lean", "lean", -0.2, 0.2),
    ("torso_offset", "torso-offset", -0.05, 0.05),
    ("hip_roll_compensation", "hip-roll", 0.0, 0.35),
    ("ankle_pitch_gyro", "ankle-pitch-gyro", -0.1, 0.4),
    ("ankle_roll_gyro", "ankle-roll-gyro", -0.1, 0.4),
]


def walks(robot):
    if "WALKS" in os.environ:
        return [tuple(float(x) for x in w.split()) for w in os.environ["WALKS"].split(";") if w.strip()]
    with open(os.path.join(ROOT, "configs/bench/motion_%s.yaml" % robot)) as f:
        t = yaml.safe_load(f)["targets"]
    v, side, turn = t["walk_forward"], t["walk_sideways"], t["turn"]
    return [(v, 0, 0, math.ceil(5 / v) + 2), (0.5 * v, 0, 0, 8), (0, 0, 0, 6),
            (-0.3 * v, 0, 0, 6), (0, side, 0, 6), (0, 0, turn, 5)]


def walk(args):
    robot, params, command = args
    vx, vy, turn, seconds = command
    cmd = [SIM, "bench", "motion", "--robot", robot, "--vx", str(vx), "--vy", str(vy),
           "--turn", str(turn), "--seconds", str(seconds)]
    for (name, knob, _, _), value in zip(SPACE, params):
        cmd += ["--" + knob, "%.5f" % value]
    out = subprocess.run(cmd, capture_output=True, text=True).stdout
    m = re.search(r"distance ([-\d.]+) m, speed ([-\d.]+) m/s, lateral ([-\d.]+) m, "
                  r"turned ([-\d.]+) rad, fell (\d) at ([-\d.]+)", out)
    if not m:
        return 0.0
    distance, speed, lateral, turned, fell, at = (float(x) for x in m.groups())
    if fell:
        return 0.5 * max(0.0, at) / seconds
    wanted = vx if vx != 0 else vy
    progress = 1.0 if wanted == 0 else max(0.0, min(1.0, speed / wanted))
    if wanted == 0 and turn == 0:
        progress = max(0.0, 1.0 - distance)  # on the spot: stay there
    drift = abs(lateral) / max(distance, 1.0)
    heading = 0.0 if turn != 0 else abs(turned) / math.pi
    if turn != 0:
        progress = max(0.0, min(1.0, turned / (turn * seconds))) if turned > 0 else 0.0
    return 0.5 + 1.5 * progress - drift - heading


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    robot, outdir = sys.argv[1], sys.argv[2]
    generations = int(sys.argv[3]) if len(sys.argv) > 3 else 30
    pop = int(sys.argv[4]) if len(sys.argv) > 4 else 16
    with open(os.path.join(ROOT, "configs/bench/motion_%s.yaml" % robot)) as f:
        motions = os.path.join(ROOT, "configs/bench", yaml.safe_load(f)["motions"])
    gait_file = os.path.join(motions, "gait.yaml")
    gait = {}
    if os.path.exists(gait_file):
        with open(gait_file) as f:
            gait = yaml.safe_load(f) or {}
    start = gait.get("walk", {})
    mean = [start.get(name, 0.5 * (lo + hi)) for name, _, lo, hi in SPACE]
    sigma = [float(os.environ.get("SIGMA", 0.25)) * (hi - lo) for _, _, lo, hi in SPACE]
    commands = walks(robot)
    os.makedirs(outdir, exist_ok=True)
    rng = random.Random(1)
    best, best_score = list(mean), -1.0
    with cf.ThreadPoolExecutor(2) as ex:
        for g in range(generations):
            cands = [list(mean)] + [
                [min(hi, max(lo, rng.gauss(m, s))) for m, s, (_, _, lo, hi) in zip(mean, sigma, SPACE)]
                for _ in range(pop - 1)]
            jobs = [(robot, c, w) for c in cands for w in commands]
            results = list(ex.map(walk, jobs))
            scores = [sum(results[i * len(commands):(i + 1) * len(commands)]) / len(commands)
                      for i in range(len(cands))]
            order = sorted(range(len(cands)), key=lambda i: -scores[i])
            if scores[order[0]] > best_score:
                best, best_score = cands[order[0]], scores[order[0]]
                out = dict(gait)
                out["walk"] = dict(start)
                out["walk"].update({name: round(v, 4) for (name, _, _, _), v in zip(SPACE, best)})
                with open(os.path.join(outdir, "gait.yaml"), "w") as f:
                    yaml.safe_dump(out, f, sort_keys=False)
            elite = [cands[i] for i in order[: max(2, pop // 4)]]
            n = len(SPACE)
            mean = [sum(e[i] for e in elite) / len(elite) for i in range(n)]
            sigma = [max(0.01 * (SPACE[i][3] - SPACE[i][2]),
                         0.7 * sigma[i] + 0.3 * math.sqrt(sum((e[i] - mean[i]) ** 2 for e in elite) / len(elite)))
                     for i in range(n)]
            print("generation %d: best %.3f (this one %.3f, mean of elite %.3f)" %
                  (g + 1, best_score, scores[order[0]], sum(scores[i] for i in order[:len(elite)]) / len(elite)),
                  flush=True)


if __name__ == "__main__":
    main()
