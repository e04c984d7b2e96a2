#!/usr/bin/env python3
"""Cross-entropy search over get-up keyframes, each candidate scored in the simulator
(`simsoccer bench motion --get-up SIDE --verbose`, seeded trials on fresh seeds each
generation): how high and upright the torso gets while the motion plays and 1.5 s after,
+2 for standing within 8 s. How configs/motions/get_up_*.yaml were found: each file's
header says with which settings (README, "Get up").

  python3 scripts/tune_get_up.py SIDE START.yaml OUTDIR [generations] [population]

SIDE: front or back. START.yaml: a get-up motion file to start from (its frames up to
the first `pose:` frame are searched; unnamed joints start from the stand pose).
Defaults: 40 generations of 24 candidates. Writes OUTDIR/get_up_SIDE.yaml (the best
single candidate so far) and OUTDIR/get_up_SIDE_mean.yaml (the search's mean, each
generation: the kept motions are means). Environment:
  SEEDS=N     trials per candidate (default 4; the kept motions used 8)
  SIGMA=R     initial spread of the joint angles, rad (default 0.25; durations 0.3 R s)
  LINEAR=1    write `interpolation: linear` (constant speed within a frame)
  ASYM=1      every joint searched on its own (default: the left side, mirrored)
  ROLL=1      the motion is a roll onto the front (`ends: front`, no stand at its end),
              scored by how far onto the front it leaves the robot, plus 2 for standing
              (after the get-up from the front) and up to +0.5 the sooner (-1 at 10 s);
              ROLL=back: a roll onto the back (`ends: back`), likewise
  SQUAT_TAIL=1  every candidate ends in a fixed deep squat and the stand
  ROBOT=NAME  nao_v6_h25 (default) or booster_k1: the robot, its motions folder
              (configs/bench/motion_NAME.yaml) and the joints searched
  SIM=PATH    the simsoccer binary (default build/apps/simsoccer)
Needs python3-yaml; runs two trials at a time."""
import atexit, math, os, random, re, shutil, subprocess, sys, tempfile, concurrent.futures as cf
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIM = os.environ.get("SIM", os.path.join(ROOT, "build/apps/simsoccer"))
EVAL = tempfile.mkdtemp(prefix="tune_get_up.")  # candidates' motion folders, removed at exit
atexit.register(shutil.rmtree, EVAL, True)
# The robot (ROBOT=nao_v6_h25 or booster_k1): the joints searched (the head's pitch and the
# left side; the right side mirrors them, with the sign of MIRROR), the torso's height standing
# (m, the score's scale), and the left-to-right name change.
ROBOT = os.environ.get("ROBOT", "nao_v6_h25")
_BENCH = yaml.safe_load(open(os.path.join(ROOT, "configs/bench/motion_%s.yaml" % ROBOT)))
MOTIONS = os.path.normpath(os.path.join(ROOT, "configs/bench", _BENCH["motions"]))
if ROBOT == "booster_k1":
    JOINTS = ["HeadPitch", "LeftShoulderPitch", "LeftShoulderRoll", "LeftElbowPitch", "LeftElbowYaw",
              "LeftHipPitch", "LeftHipRoll", "LeftHipYaw", "LeftKneePitch", "LeftAnklePitch",
              "LeftAnkleRoll"]
    SIGNS = {"ShoulderPitch": 1, "ShoulderRoll": -1, "ElbowPitch": -1, "ElbowYaw": -1, "HipPitch": 1,
             "HipRoll": -1, "HipYaw": -1, "KneePitch": 1, "AnklePitch": 1, "AnkleRoll": -1}
    right = lambda j: "Right" + j[4:]
    MIRROR = {j: (right(j), SIGNS[j[4:]]) for j in JOINTS if j.startswith("Left")}
    STAND_HEIGHT = 0.51
    ARMS = 5  # JOINTS[1:ARMS] are the left arm's, JOINTS[ARMS:] the left leg's
else:
    JOINTS = ["HeadPitch", "LShoulderPitch", "LShoulderRoll", "LElbowYaw", "LElbowRoll", "LHipYawPitch",
              "LHipRoll", "LHipPitch", "LKneePitch", "LAnklePitch", "LAnkleRoll"]
    MIRROR = {"LShoulderPitch": ("RShoulderPitch", 1), "LShoulderRoll": ("RShoulderRoll", -1),
              "LElbowYaw": ("RElbowYaw", -1), "LElbowRoll": ("RElbowRoll", -1), "LHipRoll": ("RHipRoll", -1),
              "LHipPitch": ("RHipPitch", 1), "LKneePitch": ("RKneePitch", 1), "LAnklePitch": ("RAnklePitch", 1),
              "LAnkleRoll": ("RAnkleRoll", -1)}
    right = lambda j: "R" + j[1:]
    STAND_HEIGHT = 0.33
    ARMS = 5
# ASYM=1: every joint searched on its own (no mirroring), for a motion that is not
# symmetric (the roll onto the front that starts the get-up from the back).
ASYM = bool(os.environ.get("ASYM"))
if ASYM:
    # The Nao's right HipYawPitch is its left one's (one motor, no MIRROR entry): not searched.
    legs = [right(j) for j in JOINTS[ARMS:] if j in MIRROR]
    JOINTS = ["HeadYaw"] + JOINTS[:ARMS] + [right(j) for j in JOINTS[1:ARMS]] + JOINTS[ARMS:] + legs
    MIRROR = {}
# The stand pose and the joint limits from the robot model (a left joint's range is
# narrowed to what its mirrored right joint also allows).
_ROBOT = yaml.safe_load(open(os.path.normpath(os.path.join(ROOT, "configs/bench", _BENCH["robot_model"]))))
_RANGE = {j["name"]: tuple(j["limits"]) for j in _ROBOT["joints"] if "limits" in j}
STAND = {j: float(_ROBOT["poses"]["stand"].get(j, 0.0)) for j in JOINTS}
LIMITS = {}
for _j in JOINTS:
    _lo, _hi = _RANGE[_j]
    if _j in MIRROR:
        _r, _sign = MIRROR[_j]
        _rlo, _rhi = sorted((_sign * _RANGE[_r][0], _sign * _RANGE[_r][1]))
        _lo, _hi = max(_lo, _rlo), min(_hi, _rhi)
    LIMITS[_j] = (_lo + 1e-3, _hi - 1e-3)  # inside the limits after rounding to 3 decimals
LINE = re.compile(r"^t (\S+) (\S+)\s+tilt \S+ torso z (\S+) forward (\S+) up (\S+)")

def to_vec(frames):
    v = []
    for f in frames:
        v.append(f["duration"])
        v += [f["joints"][j] for j in JOINTS]
    return v

def to_frames(v):
    frames, k = [], 0
    while k < len(v):
        d = min(max(v[k], 0.05), 1.2)
        js = {j: min(max(v[k + 1 + i], LIMITS[j][0]), LIMITS[j][1]) for i, j in enumerate(JOINTS)}
        frames.append({"duration": d, "joints": js})
        k += 1 + len(JOINTS)
    return frames

LINEAR = bool(os.environ.get("LINEAR"))  # write `interpolation: linear`
SEEDS = int(os.environ.get("SEEDS", "4"))  # seeded trials per candidate
SIGMA = float(os.environ.get("SIGMA", "0.25"))  # initial spread of the joint angles, rad

def write_yaml(side, frames, path, tail):
    out = [f"motion: get_up_{side}"] + (["interpolation: linear"] if LINEAR else []) + \
          ([f"ends: {ROLL_TO}"] if ROLL else []) + ["frames:"]
    for f in frames:
        js = {} if "HeadYaw" in f["joints"] else dict(HeadYaw=0.0)
        for j, x in f["joints"].items():
            js[j] = x
            if j in MIRROR:
                js[MIRROR[j][0]] = MIRROR[j][1] * x
        body = ", ".join(f"{j}: {x:.3f}" for j, x in js.items())
        out.append(f"  - duration: {f['duration']:.3f}")
        out.append(f"    joints: {{{body}}}")
    out += tail
    with open(path, "w") as fh:
        fh.write("\n".join(out) + "\n")

TAIL = ["  - duration: 1.0", "    pose: stand"]
# ROLL=1: the motion is a roll onto the front, ending on the ground (no stand at its
# end); scored by how far onto the front it ends, +2 when the front get-up that follows
# it stands the robot up in time.
ROLL = bool(os.environ.get("ROLL"))
ROLL_TO = "back" if os.environ.get("ROLL") == "back" else "front"
if ROLL:
    TAIL = []
if os.environ.get("SQUAT_TAIL") and ROBOT == "nao_v6_h25":
    TAIL = ["  - duration: 0.5",
            "    joints: {HeadYaw: 0.0, HeadPitch: 0.0, LShoulderPitch: 0.6, RShoulderPitch: 0.6, LShoulderRoll: 0.1, RShoulderRoll: -0.1,",
            "             LElbowYaw: 0.0, RElbowYaw: 0.0, LElbowRoll: -0.04, RElbowRoll: 0.04, LHipYawPitch: 0.0, LHipRoll: 0.0, RHipRoll: 0.0,",
            "             LHipPitch: -1.53, RHipPitch: -1.53, LKneePitch: 2.1, RKneePitch: 2.1, LAnklePitch: -1.1, RAnklePitch: -1.1,",
            "             LAnkleRoll: 0.0, RAnkleRoll: 0.0}",
            "  - duration: 0.6",
            "    joints: {LHipPitch: -1.0, RHipPitch: -1.0, LShoulderPitch: 0.5, RShoulderPitch: 0.5}",
            "  - duration: 1.0", "    pose: stand"]

def run(side, motions_dir, seed):
    p = subprocess.run([SIM, "bench", "motion", "--robot", ROBOT, "--get-up", side, "--seed", str(seed), "--motions",
                        motions_dir, "--verbose"], capture_output=True, text=True)
    rows = []
    for line in p.stderr.splitlines():
        m = LINE.match(line)
        if m:
            rows.append((float(m.group(1)), m.group(2), float(m.group(3)), float(m.group(5)),
                         float(m.group(4))))
    ok = re.search(r"standing in (\S+) s", p.stdout)
    start = next((i for i, r in enumerate(rows) if r[1] == "getting_up"), None)
    if start is None:
        return 0.0, False
    end = next((i for i in range(start, len(rows)) if rows[i][1] != "getting_up"), len(rows))
    if ROLL:
        # How far onto the front (the torso's x axis down; onto the back: up) the
        # motion leaves it, over the 0.3 s after it ends.
        after = rows[end:end + 3] or rows[-1:]
        sign = 1.0 if ROLL_TO == "back" else -1.0
        score = sum(sign * r[4] for r in after) / len(after)
        success = bool(ok) and float(ok.group(1)) < 8.0
        if ok:  # standing: +2, more the sooner (up to +0.5 at 7 s, -1 at 10 s)
            score += 2.0 + max(-1.0, min(0.5, 0.5 * (8.0 - float(ok.group(1)))))
        return score, success
    window = rows[start:min(len(rows), end + 15)]
    h = [min(r[2], STAND_HEIGHT) / STAND_HEIGHT * (0.4 + 0.6 * max(r[3], 0.0)) for r in window]
    last = h[-10:]
    score = 0.5 * max(h) + 0.5 * sum(last) / len(last)
    success = bool(ok) and float(ok.group(1)) < 8.0
    return score + (2.0 if success else 0.0), success

def evaluate(args):
    side, v, seeds, tag = args
    d = os.path.join(EVAL, tag)
    os.makedirs(d, exist_ok=True)
    for f in os.listdir(MOTIONS):
        if not os.path.exists(os.path.join(d, f)):
            shutil.copy(os.path.join(MOTIONS, f), d)
    write_yaml(side, to_frames(v), os.path.join(d, f"get_up_{side}.yaml"), TAIL)
    res = [run(side, d, s) for s in seeds]
    return sum(r[0] for r in res) / len(res), sum(r[1] for r in res)

def main():
    side, init, outdir = sys.argv[1], sys.argv[2], sys.argv[3]
    gens = int(sys.argv[4]) if len(sys.argv) > 4 else 40
    pop = int(sys.argv[5]) if len(sys.argv) > 5 else 24
    q, frames = dict(STAND), []
    for f in yaml.safe_load(open(init))["frames"]:
        if "pose" in f:
            break
        q.update({j: x for j, x in (f.get("joints") or {}).items() if j in q})
        frames.append({"duration": f["duration"], "joints": dict(q)})
    mean = to_vec(frames)
    n = len(mean)
    sig = [0.3 * SIGMA if (i % (1 + len(JOINTS))) == 0 else SIGMA for i in range(n)]
    rng = random.Random(1)
    os.makedirs(outdir, exist_ok=True)
    best = (-1, None)
    with cf.ProcessPoolExecutor(2) as ex:
        for g in range(gens):
            seeds = [1000 + SEEDS * g + k for k in range(SEEDS)]
            cands = [mean] + [[m + s * rng.gauss(0, 1) for m, s in zip(mean, sig)] for _ in range(pop - 1)]
            cands = [to_vec(to_frames(c)) for c in cands]
            scores = list(ex.map(evaluate, [(side, c, seeds, f"{side}{i}") for i, c in enumerate(cands)]))
            order = sorted(range(pop), key=lambda i: -scores[i][0])
            elite = [cands[i] for i in order[: max(2, pop // 4)]]
            if scores[order[0]][0] > best[0]:
                best = (scores[order[0]][0], cands[order[0]])
                write_yaml(side, to_frames(best[1]), os.path.join(outdir, f"get_up_{side}.yaml"), TAIL)
            mean = [sum(e[i] for e in elite) / len(elite) for i in range(n)]
            write_yaml(side, to_frames(mean), os.path.join(outdir, f"get_up_{side}_mean.yaml"), TAIL)
            sig = [max(0.02, 0.7 * s + 0.3 * math.sqrt(sum((e[i] - mean[i]) ** 2 for e in elite) / len(elite)))
                   for i, s in enumerate(sig)]
            print(f"gen {g}: best {scores[order[0]][0]:.3f} ({scores[order[0]][1]}/{SEEDS} up) mean-cand "
                  f"{scores[0][0]:.3f} ({scores[0][1]}/{SEEDS} up) overall {best[0]:.3f}", flush=True)
    write_yaml(side, to_frames(mean), os.path.join(outdir, f"get_up_{side}_mean.yaml"), TAIL)

if __name__ == "__main__":
    main()
