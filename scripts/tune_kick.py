#!/usr/bin/env python3
"""Cross-entropy search over a robot's kick parameters (the `kick:` part of its gait.yaml),
each candidate scored in the simulator: 10 kicks (`simsoccer bench motion --kick`), 5 with
each foot, the ball 2 cm inside to 2 cm outside the foot's middle, as in the motion table.
It starts from the robot's gait.yaml.
Score per kick: the distance up to TARGET + 1 m, a bonus of 1 when it reaches TARGET within
15 degrees of straight, -3 for a fall; a candidate's score is the mean.

  python3 scripts/tune_kick.py OUTDIR [generations] [population]

Writes OUTDIR/kick.txt (the best candidate so far and the search's mean, as gait.yaml
lines) after every generation. Environment:
  ROBOT=NAME   nao_v6_h25 or booster_k1 (default booster_k1): the motion bench's robot
  TARGET=M     the kick distance asked for (default 4.0)
  SIGMA=S      initial spread, a share of each parameter's start value (default 0.15)
  MODE=M       the control period, serial or pipelined (default: the bench's default), or
               both: every kick in each (the agents' kick must hold in either)
  OFFSETS=N    ball offsets per foot, evenly from -2 to +2 cm (default 5, at least 2)
  STEPS=A,B    every kick also after A, B steps on the spot (--steps-first: the kick starts from
               the sway of the last steps, as in play; default: from a settled stance only);
               with STEPS the kick's ready_time is searched too
  SIM=PATH     the simsoccer binary (default build/apps/simsoccer)
Needs python3-yaml; runs two kicks at a time."""
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
ROBOT = os.environ.get("ROBOT", "booster_k1")
TARGET = float(os.environ.get("TARGET", "4.0"))
SIGMA = float(os.environ.get("SIGMA", "0.15"))
MODE = os.environ.get("MODE")  # None: the bench's default
MODES = ["serial", "pipelined"] if MODE == "both" else [MODE]
_BENCH = yaml.safe_load(open(os.path.join(ROOT, "configs/bench/motion_%s.yaml" % ROBOT)))
_GAIT_FILE = os.path.normpath(os.path.join(ROOT, "configs/bench", _BENCH["motions"], "gait.yaml"))
# A robot without a gait.yaml (the Nao) has the code's defaults.
_KICK = ((yaml.safe_load(open(_GAIT_FILE)) or {}).get("kick", {})
         if os.path.exists(_GAIT_FILE) else {})
# The searched parameters: gait.yaml key, bench motion option, lower and upper bound.
PARAMS = [("shift", "--kick-shift", 0.02, 0.15), ("lift", "--kick-lift", 0.05, 0.25),
          ("draw_back", "--kick-draw-back", 0.0, 0.2), ("reach", "--kick-reach", 0.05, 0.3),
          ("swing_time", "--kick-swing", 0.05, 0.25),
          ("swing_height", "--kick-swing-height", 0.02, 0.15),
          ("hip_roll_compensation", "--kick-hip-roll", 0.0, 0.3),
          ("swing_out", "--kick-swing-out", -0.04, 0.04)]
STEPS = [int(x) for x in os.environ.get("STEPS", "").split(",") if x]
if STEPS:  # the wait before a kick after walking only matters after steps
    PARAMS.append(("ready_time", "--kick-ready-time", 0.0, 1.0))
# Where gait.yaml leaves a parameter out, the code's default (agents/motion/kick_engine.hpp).
DEFAULTS = {"shift": 0.052, "lift": 0.105, "draw_back": 0.08, "reach": 0.10, "swing_time": 0.05,
            "swing_height": 0.02, "hip_roll_compensation": 0.07, "swing_out": 0.0,
            "ready_time": 0.0}
START = [float(_KICK.get(k, DEFAULTS[k])) for k, _, _, _ in PARAMS]
RESULT = re.compile(r"ball (\S+) m at (\S+) deg, fell (\d)")


def clamp(v):
    return [min(max(x, lo), hi) for x, (_, _, lo, hi) in zip(v, PARAMS)]


def kick(args):
    v, foot, offset, mode, steps = args
    cmd = [SIM, "bench", "motion", "--robot", ROBOT, "--kick", "--foot", str(foot),
           "--ball-offset", str(offset), "--steps-first", str(steps)]
    if mode:
        cmd += ["--mode", mode]
    for x, (_, opt, _, _) in zip(v, PARAMS):
        cmd += [opt, "%.4f" % x]
    out = subprocess.run(cmd, capture_output=True, text=True).stdout
    m = RESULT.search(out)
    if not m:
        return -3.0
    d, angle, fell = float(m.group(1)), float(m.group(2)), int(m.group(3))
    return min(d, TARGET + 1.0) + (1.0 if d >= TARGET and abs(angle) <= 15 else 0.0) - 3.0 * fell


def main():
    outdir = sys.argv[1]
    gens = int(sys.argv[2]) if len(sys.argv) > 2 else 12
    pop = int(sys.argv[3]) if len(sys.argv) > 3 else 16
    os.makedirs(outdir, exist_ok=True)
    n = max(2, int(os.environ.get("OFFSETS", "5")))
    kicks = [(foot, -0.02 + 0.04 * k / (n - 1), mode, st) for mode in MODES for st in [0] + STEPS
             for foot in (0, 1) for k in range(n)]
    mean = list(START)
    # A share of each start value; swing_out and ready_time (near 0) on the scale of their range.
    scale = {"swing_out": 0.04, "ready_time": 1.0}
    sig = [SIGMA * scale.get(key, abs(x)) for x, (key, _, _, _) in zip(mean, PARAMS)]
    rng = random.Random(1)
    best = (-1e9, None)
    with cf.ProcessPoolExecutor(2) as ex:
        for g in range(gens):
            cands = [mean] + [clamp([m + s * rng.gauss(0, 1) for m, s in zip(mean, sig)])
                              for _ in range(pop - 1)]
            jobs = [(c, f, o, m, st) for c in cands for f, o, m, st in kicks]
            per_kick = list(ex.map(kick, jobs))
            scores = [sum(per_kick[i * len(kicks):(i + 1) * len(kicks)]) / len(kicks)
                      for i in range(pop)]
            order = sorted(range(pop), key=lambda i: -scores[i])
            elite = [cands[i] for i in order[:max(2, pop // 4)]]
            if scores[order[0]] > best[0]:
                best = (scores[order[0]], cands[order[0]])
            mean = [sum(e[i] for e in elite) / len(elite) for i in range(len(mean))]
            sig = [max(0.002, 0.7 * s + 0.3 * math.sqrt(sum((e[i] - mean[i]) ** 2 for e in elite)
                                                          / len(elite)))
                   for i, s in enumerate(sig)]
            print("gen %d: best %.3f, the mean candidate %.3f, overall %.3f" %
                  (g, scores[order[0]], scores[0], best[0]), flush=True)
            with open(os.path.join(outdir, "kick.txt"), "w") as fh:
                for name, v in (("best", best[1]), ("mean", mean)):
                    fh.write("# %s\n" % name)
                    for x, (key, _, _, _) in zip(v, PARAMS):
                        fh.write("  %s: %.4f\n" % (key, x))


if __name__ == "__main__":
    main()
