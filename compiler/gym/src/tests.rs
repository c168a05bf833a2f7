//! The environment against the runtime: a rollout records what `run` records, episodes are
//! numbered from the seed, a batch does not depend on the thread count, wrong input is an
//! error, and spec/gym.md's end table is the code.

use super::*;
use tad_policy::{EgoPolicy, EgoView};

fn example(name: &str) -> PathBuf {
    tad_test_support::repo().join("examples").join(name)
}

fn safety() -> Arc<[Scenario]> {
    let paths = [example("safety/red_light_running.tad"), example("safety/lane_changing.tad")];
    load(&paths).expect("the examples load").into()
}

/// Answers the same unit action at every step, as the environment scales it.
struct Constant([f32; 2]);

impl EgoPolicy for Constant {
    fn name(&self) -> &str {
        "constant"
    }

    fn act(&mut self, _: &EgoView) -> Action {
        Action::from_unit(self.0)
    }
}

#[test]
fn a_rollout_records_what_the_runtime_runs() {
    let scenarios = safety();
    let mut env = Env::new(Arc::clone(&scenarios), Observation::State).unwrap();
    let mut obs = vec![0.0; tad_policy::STATE_DIM];
    for (seed, action) in [(3, [0.4, 0.05]), (8, [-0.2, -0.3])] {
        env.reset(Some(seed), Some(1), &mut obs).unwrap();
        let mut t = Transition::default();
        while !(t.terminated || t.truncated) {
            t = env.step(action, &mut obs).unwrap();
        }
        let info = env.info().unwrap();
        let scene = &scenarios[1].scene;
        let params = tad_runtime::sample::sample(&scene.program.params, Some(seed));
        let ran = tad_runtime::run(scene, Some(seed), params, &mut Constant(action), &Options::default());
        assert_eq!((info.seed, info.stop_reason), (seed, Some(ran.stop_reason)));
        assert_eq!(info.records, ran.records.as_slice());
        assert_eq!(t.terminated, terminates(ran.stop_reason));
        assert_eq!(env.step(action, &mut obs), Err(GymError::NotRunning));
    }
}

#[test]
fn episodes_are_numbered_from_the_seed() {
    let mut env = Env::new(safety(), Observation::SafeBench).unwrap();
    let mut obs = [0.0; 4];
    env.reset(Some(10), None, &mut obs).unwrap();
    let first = (env.info().unwrap().index, env.info().unwrap().seed);
    env.reset(None, None, &mut obs).unwrap();
    let second = (env.info().unwrap().index, env.info().unwrap().seed);
    assert_eq!([first, second], [(0, 10), (1, 11)]);
    env.reset(Some(10), None, &mut obs).unwrap();
    assert_eq!(env.info().unwrap().seed, 10, "a seed starts the numbering again");

    let mut batch = Batch::new(safety(), Observation::SafeBench, 3).unwrap();
    let mut rows = [0.0; 12];
    batch.reset(Some(5), &mut rows).unwrap();
    let seeds: Vec<u64> = (0..3).map(|i| batch.env(i).info().unwrap().seed).collect();
    assert_eq!(seeds, [5, 6, 7]);
}

/// Every environment's rewards over `steps` steps of a batch of 5, on `threads` threads.
fn rewards_on(threads: usize, steps: usize) -> Vec<f64> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut batch = Batch::new(safety(), Observation::State, 5).unwrap();
        let width = tad_policy::STATE_DIM;
        let mut obs = vec![0.0; 5 * width];
        batch.reset(Some(1), &mut obs).unwrap();
        let (mut rewards, mut term, mut trunc) = (vec![0.0; 5], vec![0; 5], vec![0; 5]);
        let mut all = Vec::new();
        for k in 0..steps {
            let actions: Vec<f32> = (0..10).map(|j| ((k * 7 + j * 3) % 11) as f32 / 5.0 - 1.0).collect();
            let out = Outputs { obs: &mut obs, rewards: &mut rewards, terminated: &mut term, truncated: &mut trunc };
            batch.step(&actions, out).unwrap();
            all.extend(&rewards);
            all.extend(obs.iter().map(|&v| f64::from(v)));
        }
        all
    })
}

#[test]
fn a_batch_does_not_depend_on_the_thread_count() {
    // 400 steps: every environment ends an episode and is reset on the way
    assert_eq!(rewards_on(1, 400), rewards_on(3, 400));
}

#[test]
fn wrong_input_is_an_error() {
    let mut env = Env::new(safety(), Observation::SafeBench).unwrap();
    let mut obs = [0.0; 4];
    assert_eq!(env.step([0.0, 0.0], &mut obs), Err(GymError::NotRunning));
    assert!(matches!(env.reset(None, None, &mut [0.0; 3]), Err(GymError::Shape(_))));
    assert!(matches!(env.reset(None, Some(2), &mut obs), Err(GymError::Shape(_))));
    env.reset(None, None, &mut obs).unwrap();
    // not finite: no action
    assert!(env.step([f32::NAN, f32::INFINITY], &mut obs).is_ok());
    assert_eq!(
        observation("pixels").unwrap_err().to_string(),
        "unknown observation `pixels` (expected `safebench` or `state`)"
    );

    let mut batch = Batch::new(safety(), Observation::SafeBench, 2).unwrap();
    let mut rows = [0.0; 8];
    batch.reset(None, &mut rows).unwrap();
    let (mut r, mut a, mut b) = ([0.0; 2], [0; 2], [0; 2]);
    let out = Outputs { obs: &mut rows, rewards: &mut r, terminated: &mut a, truncated: &mut b };
    assert!(matches!(batch.step(&[0.0; 3], out), Err(GymError::Shape(_))));

    let dir = std::env::temp_dir().join(format!("tad-gym-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.tad");
    std::fs::write(&bad, "scenario x {\n  ego: car\n  weather: snowy_sunshine\n}\n").unwrap();
    let corrupt = dir.join("bad.tadc");
    std::fs::write(&corrupt, b"TADC\x00garbage").unwrap();
    let Err(GymError::Load(reports)) = load(&[bad, corrupt, dir.join("missing.tad")]) else {
        panic!("the files should not load");
    };
    assert_eq!(reports.len(), 3, "{reports:#?}");
    assert!(reports.iter().any(|r| r.contains("bad.tad: not loaded: it has errors")), "{reports:#?}");
    assert!(reports.iter().any(|r| r.contains("bad.tadc: not loaded")), "{reports:#?}");
    assert!(matches!(load(&[]), Err(GymError::NoScenario)));
}

#[test]
fn the_specs_end_table_is_the_code() {
    // spec/gym.md §3: each stop reason in one row, terminated or truncated as `terminates`
    let spec = std::fs::read_to_string(tad_test_support::repo().join("spec/gym.md")).unwrap();
    let mut said = std::collections::HashMap::new();
    for line in spec.lines().filter(|l| l.ends_with("| `terminated` |") || l.ends_with("| `truncated` |")) {
        let terminated = line.ends_with("| `terminated` |");
        for name in line.split('`').skip(1).step_by(2).filter(|n| !["terminated", "truncated"].contains(n)) {
            assert!(said.insert(name.to_string(), terminated).is_none(), "{name} is listed twice");
        }
    }
    for reason in StopReason::ALL {
        assert_eq!(said.remove(reason.as_str()), Some(terminates(reason)), "{}", reason.as_str());
    }
    assert!(said.is_empty(), "the spec lists stop reasons the runtime does not have: {said:?}");
}
