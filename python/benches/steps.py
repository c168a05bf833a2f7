"""Steps per second through the Python boundary, against peers measured in the same run.

    python python/benches/steps.py [--tadslc target/release/tadslc] [--seconds 5]

1. `tadslc run` on the same scenes (in-process Rust; `--ego naive`, many seeds, steps
   counted from its JSON lines; start-up and compilation included, amortised over the
   episodes);
2. `tadsl`'s vector environment with 8 environments (one `step` moves 8 scenes), and the
   single environment, driven by constant actions (no policy cost on either side);
3. highway-env's `highway-fast-v0` (PyPI) with as many vehicles as the scenes have actors.

Build both sides the same way (release) before measuring.
"""

import argparse
import json
import os
import subprocess
import time

import gymnasium
import numpy as np

import tadsl

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = [os.path.join(REPO, "examples", "safety")]


def timed(step, seconds):
    """Calls of `step` (returning how many scene steps it made) for about `seconds`."""
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        steps += step()
    return steps / (time.perf_counter() - start)


def run_cli(tadslc, seeds):
    start = time.perf_counter()
    out = subprocess.run([tadslc, "run", *SCENES, "--ego", "naive", "--seeds", f"0..{seeds}", "--format", "json"],
                         capture_output=True, text=True, check=True).stdout
    elapsed = time.perf_counter() - start
    steps = sum(json.loads(l).get("steps", 0) for l in out.splitlines() if '"aggregate"' not in l)
    return steps / elapsed


def vector(n, seconds):
    env = tadsl.ScenarioVectorEnv(SCENES, num_envs=n)
    env.reset(seed=0)
    actions = np.zeros((n, 2), dtype=np.float32)
    actions[:, 0] = 0.3

    def step():
        env.step(actions)
        return n

    return timed(step, seconds)


def episodes(env, seconds):
    """Steps/s of one Gymnasium environment driven by a constant action, reset as its
    episodes end."""
    env.reset(seed=0)
    action = np.array([0.3, 0.0], dtype=np.float32)

    def step():
        _, _, term, trunc, _ = env.step(action)
        if term or trunc:
            env.reset()
        return 1

    return timed(step, seconds)


def single(seconds):
    return episodes(gymnasium.make("tadsl/Scenario-v0", scenarios=SCENES, disable_env_checker=True), seconds)


def highway(vehicles, seconds):
    import highway_env  # noqa: F401

    env = gymnasium.make("highway-fast-v0", config={"vehicles_count": vehicles, "action": {"type": "ContinuousAction"}})
    return episodes(env, seconds)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--tadslc", default=os.path.join(REPO, "target", "release", "tadslc"))
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--seeds", type=int, default=40)
    args = parser.parse_args()
    cli = run_cli(args.tadslc, args.seeds)
    vec8 = vector(8, args.seconds)
    one = single(args.seconds)
    hw = highway(14, args.seconds)
    print(f"tadslc run (in-process Rust, naive ego):    {cli:10.0f} scene steps/s")
    print(f"tadsl vector env, 8 scenes per step:        {vec8:10.0f} scene steps/s  ({cli / vec8:.2f}x slower than tadslc run)")
    print(f"tadsl single env (gymnasium.make):          {one:10.0f} scene steps/s  ({cli / one:.2f}x slower)")
    print(f"highway-env highway-fast-v0, 14 vehicles:   {hw:10.0f} steps/s        (tadsl vector env {vec8 / hw:.1f}x faster)")


if __name__ == "__main__":
    main()
