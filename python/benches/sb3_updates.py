"""Stable-Baselines3's learning steps per second, the peer of `tadslc bench --rl`.

One algorithm, the same networks (two hidden layers of the given width), batch sizes and
threads as TADSL's measurement, on a stand-in environment of the same observation and
action widths: only the update is timed, so the environment does not matter. Prints one
JSON object: {"algo", "threads", "updates", "seconds", "updates_per_s"}.
"""

import argparse
import json
import time

import gymnasium as gym
import numpy as np
import torch


class Blank(gym.Env):
    """Observation and action boxes of the given widths; nothing else."""

    def __init__(self, obs, act=2):
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (obs,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (act,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return self.observation_space.sample(), {}

    def step(self, action):
        return self.observation_space.sample(), 0.0, False, False, {}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--algo", choices=["ppo", "sac", "td3"], required=True)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--updates", type=int, default=200)
    p.add_argument("--batch", type=int, default=256)
    p.add_argument("--hidden", type=int, default=256)
    p.add_argument("--obs", type=int, default=13)
    p.add_argument("--rollout", type=int, default=2048)
    p.add_argument("--epochs", type=int, default=2)
    a = p.parse_args()
    torch.set_num_threads(a.threads)
    from stable_baselines3 import PPO, SAC, TD3
    from stable_baselines3.common.logger import Logger

    env = Blank(a.obs)
    kwargs = dict(policy_kwargs=dict(net_arch=[a.hidden, a.hidden]), device="cpu", seed=0, verbose=0)
    if a.algo == "ppo":
        model = PPO("MlpPolicy", env, n_steps=a.rollout, batch_size=a.batch, n_epochs=a.epochs, **kwargs)
        model.set_logger(Logger(None, []))  # SB3's default logger makes a directory in /tmp
        model.learn(total_timesteps=1)  # fills the rollout and trains once (warm-up)
        start = time.perf_counter()
        model.train()
        seconds = time.perf_counter() - start
        updates = a.epochs * -(-a.rollout // a.batch)
    else:
        cls = SAC if a.algo == "sac" else TD3
        model = cls("MlpPolicy", env, batch_size=a.batch, learning_starts=0, buffer_size=10_000, **kwargs)
        model.set_logger(Logger(None, []))
        model.learn(total_timesteps=a.batch + 1)
        model.train(gradient_steps=10, batch_size=a.batch)  # warm-up
        start = time.perf_counter()
        model.train(gradient_steps=a.updates, batch_size=a.batch)
        seconds = time.perf_counter() - start
        updates = a.updates
    print(json.dumps({"algo": a.algo, "threads": a.threads, "updates": updates, "seconds": seconds,
                      "updates_per_s": updates / seconds}))


if __name__ == "__main__":
    main()
