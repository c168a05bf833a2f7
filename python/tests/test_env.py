"""The Gymnasium environment: Gymnasium's own checker, rollouts against `tadslc run`, the
vector environment against single ones, the policy loader against NumPy, wrong input."""

import json
import subprocess

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import tadsl

SAFETY = ["examples/safety/lane_changing.tad", "examples/safety/red_light_running.tad"]


def scenarios(repo):
    return [str(repo / p) for p in SAFETY]


@pytest.mark.parametrize("observation", ["safebench", "state"])
def test_check_env_passes(repo, observation):
    env = gymnasium.make("tadsl/Scenario-v0", scenarios=scenarios(repo), observation=observation, seed=1)
    check_env(env.unwrapped, skip_render_check=True)
    obs, _ = env.reset(seed=2)
    assert obs.shape == ((4,) if observation == "safebench" else (tadsl.STATE_DIM,))


def test_a_rollout_is_what_tadslc_run_records(repo, tadslc, tmp_path):
    # actions of k/8 are exact in binary, so their scaled values cross the JSON protocol
    # unchanged
    rng = np.random.default_rng(5)
    env = tadsl.ScenarioEnv(scenarios(repo), observation="state")
    seed = 7
    _, info = env.reset(seed=seed, options={"scenario": 1})
    assert (info["seed"], info["scenario_index"]) == (seed, 1)
    physical, done = [], False
    while not done:
        acc, steer = rng.integers(-8, 9, size=2) / 8
        # tad_policy::Action::from_unit: 3 m/s² forward, the full brake (8 m/s²) backward
        scale = 3.0 if acc >= 0 else 8.0
        physical.append([scale * float(np.float32(acc)), 0.3 * float(np.float32(steer))])
        _, _, terminated, truncated, info = env.step(np.array([acc, steer], dtype=np.float32))
        done = terminated or truncated
    records = env.records()
    (tmp_path / "actions.json").write_text(json.dumps(physical))
    trace = tmp_path / "trace.jsonl"
    ego = f"external:python3 {repo / 'python/tests/replay.py'} {tmp_path / 'actions.json'}"
    run = subprocess.run(
        [tadslc, "run", scenarios(repo)[1], "--ego", ego, "--seeds", str(seed), "--format", "json",
         "--trace", str(trace)],
        capture_output=True, text=True, check=False,
    )
    assert run.returncode == 0, run.stderr
    episode = json.loads(run.stdout.splitlines()[0])
    assert (episode["steps"], episode["stop_reason"]) == (info["steps"], info["stop_reason"])
    poses = [json.loads(line)["actors"][0] for line in trace.read_text().splitlines()][1:]
    assert len(poses) == len(records)
    for pose, (_, x, y, yaw_deg, speed, _, _) in zip(poses, records):
        # the trace rounds to mm and mm/s; a value at a rounding boundary may round either way
        assert [pose["x"], pose["y"], pose["v"]] == pytest.approx([x, y, speed], abs=5.01e-4)
        assert pose["yaw"] == pytest.approx(np.radians(-yaw_deg), abs=2e-3)


def test_the_vector_env_steps_what_single_envs_step(repo):
    n, seed = 3, 11
    vec = gymnasium.make_vec("tadsl/Scenario-v0", num_envs=n, vectorization_mode="vector_entry_point",
                             scenarios=scenarios(repo), observation="safebench")
    singles = [tadsl.ScenarioEnv(scenarios(repo)) for _ in range(n)]
    obs, _ = vec.reset(seed=seed)
    for i, env in enumerate(singles):
        first, info = env.reset(seed=seed + i, options={"scenario": i % 2})
        np.testing.assert_array_equal(obs[i], first)
    rng = np.random.default_rng(3)
    episodes = [0] * n  # how many episodes each environment has ended
    pending = np.zeros(n, dtype=bool)
    for _ in range(400):
        actions = rng.uniform(-1, 1, size=(n, 2)).astype(np.float32)
        obs, rewards, terminated, truncated, _ = vec.step(actions)
        for i, env in enumerate(singles):
            if pending[i]:
                # next-step autoreset: environment i's next episode is number i + k·n
                number = i + episodes[i] * n
                first, _ = env.reset(seed=seed + number, options={"scenario": number % 2})
                assert (rewards[i], terminated[i], truncated[i]) == (0.0, False, False)
                np.testing.assert_array_equal(obs[i], first)
                continue
            single = env.step(actions[i])
            np.testing.assert_array_equal(obs[i], single[0])
            assert (rewards[i], terminated[i], truncated[i]) == single[1:4]
        pending = terminated | truncated
        episodes = [e + int(p) for e, p in zip(episodes, pending)]
    assert min(episodes) >= 1, f"every environment should end an episode in 400 steps: {episodes}"


def test_an_sb3_ppo_policy_loads_as_numpy_computes_it(tmp_path):
    rng = np.random.default_rng(1)
    dim = tadsl.STATE_DIM
    path = tmp_path / "ppo.safetensors"
    state = hand_written_ppo(path, seed=0, scale=6.0)
    policy = tadsl.Policy(str(path))
    assert (policy.format, policy.obs_len) == ("SB3 PPO", dim)
    for _ in range(5):
        obs = rng.normal(size=dim).astype(np.float32)
        x = np.tanh(state["mlp_extractor.policy_net.0.weight"] @ obs + state["mlp_extractor.policy_net.0.bias"])
        x = np.tanh(state["mlp_extractor.policy_net.2.weight"] @ x + state["mlp_extractor.policy_net.2.bias"])
        want = np.clip(state["action_net.weight"] @ x + state["action_net.bias"], -1, 1)
        np.testing.assert_allclose(policy.act(obs.astype(float).tolist()), want, atol=1e-5)
    with pytest.raises(ValueError, match="reads 13 values, not 4"):
        policy.act([0.0] * 4)


def test_wrong_input_is_a_clear_error(repo, tmp_path):
    bad = tmp_path / "bad.tad"
    bad.write_text("scenario x {\n  ego: car\n  weather: snowy_sunshine\n}\n")
    with pytest.raises(ValueError, match="bad.tad: not loaded: it has errors"):
        tadsl.ScenarioEnv([str(bad)])
    with pytest.raises(ValueError, match="unknown observation `pixels`"):
        tadsl.ScenarioEnv(scenarios(repo), observation="pixels")
    env = tadsl.ScenarioEnv(scenarios(repo))
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(np.zeros(2, dtype=np.float32))
    with pytest.raises(ValueError, match="no such file|cannot be read|not found|does not exist"):
        tadsl.ScenarioEnv([str(tmp_path / "missing.tad")])


def hand_written_ppo(path, seed=0, scale=1.0):
    """An SB3 PPO `state_dict` of SB3's names and shapes (no PyTorch needed), saved to
    `path`; returns the tensors."""
    from safetensors.numpy import save_file

    rng = np.random.default_rng(seed)
    w = lambda *shape: rng.uniform(-0.5, 0.5, size=shape).astype(np.float32)
    dim = tadsl.STATE_DIM
    state = {
        "mlp_extractor.policy_net.0.weight": w(64, dim), "mlp_extractor.policy_net.0.bias": w(64),
        "mlp_extractor.policy_net.2.weight": w(64, 64), "mlp_extractor.policy_net.2.bias": w(64),
        "mlp_extractor.value_net.0.weight": w(64, dim), "mlp_extractor.value_net.0.bias": w(64),
        "action_net.weight": w(2, 64) * scale, "action_net.bias": w(2), "log_std": w(2),
        "value_net.weight": w(1, 64), "value_net.bias": w(1),
    }
    save_file(state, str(path))
    return state


def test_an_sb3_policy_drives_as_learned(repo, tadslc, tmp_path):
    # the same policy driving the environment from Python and `tadslc run --ego learned:`
    # gives the same episode
    path = tmp_path / "ppo.safetensors"
    hand_written_ppo(path, seed=4, scale=0.2)
    policy = tadsl.Policy(str(path))
    scenario, seed = scenarios(repo)[0], 2
    env = tadsl.ScenarioEnv([scenario], observation="state")
    obs, _ = env.reset(seed=seed)
    done = False
    while not done:
        acc, steer = policy.act([float(v) for v in obs])
        obs, _, terminated, truncated, info = env.step(np.array([acc, steer], dtype=np.float32))
        done = terminated or truncated
    run = subprocess.run([tadslc, "run", scenario, "--ego", f"learned:{path}", "--seeds", str(seed), "--format", "json"],
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    episode = json.loads(run.stdout.splitlines()[0])
    assert episode["ego"] == f"learned:{path}"
    assert (episode["steps"], episode["stop_reason"]) == (info["steps"], info["stop_reason"])


def test_the_junit_report_validates_and_fail_on_sets_the_status(repo, tadslc, tmp_path):
    """Against the JUnit schema Jenkins' xUnit plugin publishes (`junit-10.xsd`, shipped in
    pytest's sdist; CI sets TADSL_JUNIT_XSD)."""
    import os

    xsd = os.environ.get("TADSL_JUNIT_XSD")
    if not xsd:
        if os.environ.get("CI"):
            pytest.fail("TADSL_JUNIT_XSD is not set: CI validates the JUnit report against junit-10.xsd")
        pytest.skip("TADSL_JUNIT_XSD not set")
    import xmlschema

    schema = xmlschema.XMLSchema(xsd)
    report = tmp_path / "report.xml"
    base = [tadslc, "run", str(repo / "examples/safety"), "--ego", "idm,naive", "--seeds", "0..2", "--junit", str(report)]
    gate = subprocess.run(base + ["--fail-on", "collision,red_light"], capture_output=True, text=True, check=False)
    assert gate.returncode == 1, gate.stderr
    assert "--fail-on:" in gate.stderr
    schema.validate(str(report))
    text = report.read_text()
    assert text.count("<testcase ") == 8 * 2 * 2 and '<failure type="collision"' in text
    # a broken report does not validate: the check can fail
    with pytest.raises(xmlschema.XMLSchemaValidationError):
        schema.validate(text.replace("<testcase ", "<testcas ", 1).replace("</testcase>", "</testcas>", 1))
    calm = subprocess.run(base, capture_output=True, text=True, check=False)
    assert calm.returncode == 0, calm.stderr
