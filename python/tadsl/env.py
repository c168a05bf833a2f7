"""The Gymnasium classes around the native environments (``tadsl._tadsl``).

The native side owns the episodes (which scenario, which seed, SafeBench's reward, when an
episode ends); these classes give them Gymnasium's spaces and signatures and hold the NumPy
buffers the native side writes into.
"""

from __future__ import annotations

import os
from typing import Any, Iterable, Optional, Union

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from tadsl import _tadsl

Scenarios = Union[str, os.PathLike, Iterable[Union[str, os.PathLike]]]


def _paths(scenarios: Scenarios) -> list[str]:
    if isinstance(scenarios, (str, os.PathLike)):
        return [os.fspath(scenarios)]
    paths = [os.fspath(p) for p in scenarios]
    if not paths:
        raise ValueError("no scenario to run: give scenario files or directories")
    return paths


def _no_render(render_mode: Optional[str]) -> None:
    # libraries ask for "rgb_array" by default (SB3's make_vec_env); drawing is tadslc's job
    if render_mode is not None:
        gymnasium.logger.warn(f"render_mode {render_mode!r} is ignored: draw episodes with `tadslc run --render`")


def _spaces(obs_len: int) -> tuple[spaces.Box, spaces.Box]:
    observation = spaces.Box(-np.inf, np.inf, shape=(obs_len,), dtype=np.float32)
    action = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
    return observation, action


class ScenarioEnv(gymnasium.Env):
    """One ego driving through TADSL scenarios, one episode per ``reset``.

    Episode ``e`` after ``reset(seed=s)`` runs scenario ``e mod N`` with seed ``s + e``
    (``options={"scenario": i}`` or a name pins the scenario). The action is ``[acc, steer]``
    in ``[-1, 1]``, scaled as SafeBench scales its actors' (3 m/s² forward, 8 m/s² braking, 0.3 of full lock).
    """

    metadata = {"render_modes": []}

    def __init__(self, scenarios: Scenarios, observation: str = "safebench", seed: Optional[int] = None,
                 render_mode: Optional[str] = None):
        _no_render(render_mode)
        self._core = _tadsl.Env(_paths(scenarios), observation)
        self.observation_space, self.action_space = _spaces(self._core.obs_len)
        self.scenario_names = list(self._core.scenarios)
        self._obs = np.zeros(self._core.obs_len, dtype=np.float32)
        self._first_seed = seed

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None):
        super().reset(seed=seed)
        if seed is None:
            seed, self._first_seed = self._first_seed, None
        scenario = (options or {}).get("scenario")
        if isinstance(scenario, str):
            scenario = self.scenario_names.index(scenario)
        self._core.reset(seed, scenario, self._obs)
        return self._obs.copy(), self._core.info()

    def step(self, action):
        acc, steer = np.asarray(action, dtype=np.float32).reshape(2)
        reward, terminated, truncated = self._core.step(float(acc), float(steer), self._obs)
        return self._obs.copy(), reward, terminated, truncated, self._core.info()

    def records(self) -> list[tuple]:
        """The episode's step records as ``tadslc run`` keeps them: ``(time, x, y, yaw_deg,
        speed, collision, route_complete)`` per step."""
        return self._core.records()


class ScenarioVectorEnv(VectorEnv):
    """``num_envs`` environments stepped together in Rust threads (the GIL released).

    Environment ``i`` after ``reset(seed=s)`` runs episodes ``i, i + n, i + 2n, ...`` as
    :class:`ScenarioEnv` numbers them. An environment whose episode ended is reset at the
    next ``step`` (Gymnasium's next-step autoreset: its action ignored, reward 0).
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, scenarios: Scenarios, num_envs: int = 8, observation: str = "safebench",
                 seed: Optional[int] = None, render_mode: Optional[str] = None):
        _no_render(render_mode)
        self._core = _tadsl.VecEnv(_paths(scenarios), observation, num_envs)
        self.num_envs = num_envs
        self.single_observation_space, self.single_action_space = _spaces(self._core.obs_len)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._obs = np.zeros((num_envs, self._core.obs_len), dtype=np.float32)
        self._rewards = np.zeros(num_envs, dtype=np.float64)
        self._terminated = np.zeros(num_envs, dtype=np.uint8)
        self._truncated = np.zeros(num_envs, dtype=np.uint8)
        self._first_seed = seed

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None):
        if isinstance(seed, (list, tuple)):
            raise ValueError("give one seed: environment i numbers its episodes from seed + i")
        super().reset(seed=seed)
        if seed is None:
            seed, self._first_seed = self._first_seed, None
        self._core.reset(seed, self._obs)
        return self._obs.copy(), {}

    def step(self, actions):
        actions = np.ascontiguousarray(actions, dtype=np.float32).reshape(self.num_envs, 2)
        self._core.step(actions, self._obs, self._rewards, self._terminated, self._truncated)
        return (self._obs.copy(), self._rewards.copy(), self._terminated.astype(bool),
                self._truncated.astype(bool), {})

    def episode_info(self, i: int) -> dict[str, Any]:
        """Environment ``i``'s episode: scenario, seed, stop reason, steps, return."""
        return self._core.info(i)
