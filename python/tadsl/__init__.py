"""TADSL's traffic scenarios as Gymnasium environments.

``gymnasium.make("tadsl/Scenario-v0", scenarios=[...], observation="safebench" | "state" | "kinematics",
seed=...)`` drives the ego through TADSL scenario files (``.tad``, ``.yaml``, ``.tadc``) on
TADSL's runtime, with SafeBench's observation, action and reward. ``gymnasium.make_vec(
"tadsl/Scenario-v0", num_envs=8, vectorization_mode="vector_entry_point", scenarios=...)``
steps many scenes together in Rust threads. ``Policy(path)`` loads a learned policy as
``tadslc run --ego learned:PATH`` does. The environment is specified in the repository's
``spec/gym.md``.
"""

import gymnasium

from tadsl._tadsl import STATE_DIM, Policy
from tadsl.env import ScenarioEnv, ScenarioVectorEnv

__all__ = ["STATE_DIM", "Policy", "ScenarioEnv", "ScenarioVectorEnv"]

ENV_ID = "tadsl/Scenario-v0"

if ENV_ID not in gymnasium.registry:
    gymnasium.register(
        id=ENV_ID,
        entry_point="tadsl.env:ScenarioEnv",
        vector_entry_point="tadsl.env:ScenarioVectorEnv",
        disable_env_checker=False,
    )
