"""Train Stable-Baselines3's PPO on TADSL scenes, then export the policy for `tadslc run`.

    pip install -e "python[sb3]"    # or: pip install stable-baselines3 safetensors
    python python/examples/train_ppo.py examples/safety --steps 20000 --out ppo.safetensors
    tadslc run examples/safety --ego idm,learned:ppo.safetensors --seeds 0..5

The environment is `tadsl/Scenario-v0` with the 13-value `state` observation; the policy is
SB3's default MLP (64-64, tanh). Its `state_dict()` goes to safetensors with SB3's own names,
which `--ego learned:` reads (spec/gym.md §5). Seeded: the same seed and thread count give
the same file.
"""

import argparse

import gymnasium
import torch
from safetensors.torch import save_file
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env

import tadsl  # noqa: F401  (registers tadsl/Scenario-v0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="+", help="scenario files or directories")
    parser.add_argument("--steps", type=int, default=20_000, help="environment steps to train for")
    parser.add_argument("--envs", type=int, default=4, help="environments stepped together")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="ppo.safetensors")
    args = parser.parse_args()

    torch.manual_seed(args.seed)
    env = make_vec_env("tadsl/Scenario-v0", n_envs=args.envs, seed=args.seed,
                       env_kwargs={"scenarios": args.scenarios, "observation": "state"})
    model = PPO("MlpPolicy", env, seed=args.seed, n_steps=512, batch_size=128, verbose=1, device="cpu")
    model.learn(total_timesteps=args.steps)

    tensors = {name: t.detach().contiguous() for name, t in model.policy.state_dict().items()}
    save_file(tensors, args.out, metadata={"activation": "tanh", "algorithm": "ppo"})
    check = tadsl.Policy(args.out)
    print(f"wrote {args.out} ({check.format}, reads {check.obs_len} values); "
          f"drive it: tadslc run {' '.join(args.scenarios)} --ego learned:{args.out}")

    # the exported policy answers what SB3's deterministic predict answers
    probe = gymnasium.make("tadsl/Scenario-v0", scenarios=args.scenarios, observation="state")
    obs, _ = probe.reset(seed=args.seed)
    ours = check.act([float(v) for v in obs])
    theirs, _ = model.predict(obs, deterministic=True)
    assert max(abs(a - b) for a, b in zip(ours, theirs)) < 1e-4, (ours, theirs)


if __name__ == "__main__":
    main()
