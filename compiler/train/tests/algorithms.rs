//! TD3 and PPO beside SAC: each improves its return on a small task, a resumed run equals
//! the unbroken one, parallel rounds do not depend on the thread count, and the DAgger warm
//! start clones the idm driver.

mod common;

use common::{mean_return, params, scene, small, temp};
use tad_policy::{EgoPolicy, Idm, Observation};
use tad_runtime::Scene;
use tad_train::{Algo, Config, Imitation, Job, TrainScene, Trainer};

fn config(algo: Algo, seed: u64) -> Config {
    let base = small(seed);
    match algo {
        Algo::Sac => base,
        Algo::Td3 => Config { algo, explore_noise: 0.2, ..base },
        Algo::Ppo => Config { algo, rollout: 400, batch: 64, epochs: 10, actor_lr: 1e-3, critic_lr: 1e-3, ..base },
    }
}

/// Rounds of `envs` episodes on `scenes` until `until` episodes in all.
fn rounds(trainer: &mut Trainer, scenes: &[Scene], until: u64) {
    let scenes: Vec<TrainScene> = scenes.iter().map(|scene| TrainScene { scene, fixed: None }).collect();
    while trainer.episodes() < until {
        let count = (trainer.config().envs as u64).min(until - trainer.episodes()) as usize;
        let jobs = trainer.jobs(&scenes, count);
        trainer.round(&jobs).expect("a round");
    }
}

#[test]
fn td3_and_ppo_improve_their_return() {
    let scenes = [scene(80, false), scene(80, true)];
    for (algo, episodes) in [(Algo::Td3, 100), (Algo::Ppo, 160)] {
        let mut trainer = Trainer::new(Config { envs: 4, ..config(algo, 3) }).expect("a trainer");
        let before = mean_return(&trainer, &scenes);
        rounds(&mut trainer, &scenes, episodes);
        let after = mean_return(&trainer, &scenes);
        eprintln!("{}: return {before:.1} -> {after:.1}, {} updates", algo.name(), trainer.updates());
        assert!(trainer.updates() > 0, "{}: learning started", algo.name());
        assert!(after > before + 100.0, "{}: return {before:.1} -> {after:.1}", algo.name());
    }
}

#[test]
fn every_algorithm_resumes_as_the_unbroken_run() {
    let scenes = [scene(30, false), scene(30, true)];
    for algo in Algo::ALL {
        let config = Config {
            start_training: 40,
            updates_per_episode: 2,
            batch: 32,
            rollout: 60,
            epochs: 2,
            envs: 2,
            ..config(algo, 9)
        };
        let dir = temp(&format!("resume-{}", algo.name()));
        let mut whole = Trainer::new(config.clone()).expect("a trainer");
        rounds(&mut whole, &scenes, 8);
        whole.save_checkpoint(dir.join("whole.ckpt")).expect("saved");

        let mut first = Trainer::new(config.clone()).expect("a trainer");
        rounds(&mut first, &scenes, 4);
        assert!(first.updates() > 0, "{}: the first half learns already", algo.name());
        first.save_checkpoint(dir.join("half.ckpt")).expect("saved");
        drop(first);
        let mut second = Trainer::load_checkpoint(dir.join("half.ckpt")).expect("loaded");
        rounds(&mut second, &scenes, 8);
        second.save_checkpoint(dir.join("resumed.ckpt")).expect("saved");
        for file in
            ["actor.safetensors", "critics.safetensors", "optimizer.safetensors", "replay.safetensors", "state.json"]
        {
            let a = std::fs::read(dir.join("whole.ckpt").join(file)).expect("read");
            let b = std::fs::read(dir.join("resumed.ckpt").join(file)).expect("read");
            assert!(a == b, "{}: {file} differs after a resume", algo.name());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn a_round_does_not_depend_on_the_thread_count() {
    let scenes = [scene(40, false), scene(40, true)];
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a pool");
        pool.install(|| {
            let mut trainer =
                Trainer::new(Config { envs: 6, start_training: 50, ..config(Algo::Td3, 5) }).expect("a trainer");
            rounds(&mut trainer, &scenes, 12);
            let dir = temp(&format!("threads-{threads}"));
            trainer.save_actor(dir.join("actor.safetensors")).expect("saved");
            let bytes = std::fs::read(dir.join("actor.safetensors")).expect("read");
            let _ = std::fs::remove_dir_all(&dir);
            (bytes, trainer.updates())
        })
    };
    let (one, updates) = run(1);
    assert!(updates > 0);
    assert_eq!(one, run(3).0, "1 and 3 threads give the same actor");
}

#[test]
fn dagger_clones_the_idm_driver() {
    let scenes = [scene(80, false), scene(80, true)];
    let trained: Vec<TrainScene> = scenes.iter().map(|scene| TrainScene { scene, fixed: None }).collect();
    for algo in Algo::ALL {
        let config = Config { observation: Observation::State, ..config(algo, 4) };
        let mut trainer = Trainer::new(config.clone()).expect("a trainer");
        let make = || -> Box<dyn EgoPolicy> { Box::new(Idm::default()) };
        let mut rounds = Vec::new();
        let settings = Imitation { rounds: 3, episodes: 8, epochs: 20, ..Imitation::default() };
        trainer.imitate(&trained, &make, &settings, |r| rounds.push(r.clone())).expect("imitated");
        assert_eq!(rounds.len(), 3);
        assert_eq!(rounds[0].driver, "teacher");
        let last = rounds.last().expect("a round");
        assert!(last.loss < 0.01, "{}: the fit's error {}", algo.name(), last.loss);
        // the clone drives as the teacher does: as far, without a collision (not as
        // rewarded: a clone a hair above the desired speed pays SafeBench's 10 a step)
        for scene in &scenes {
            let p = params(scene, 11);
            let clone = trainer.evaluate(scene, p.clone(), 11);
            let teacher = tad_train::evaluate(scene, p, 11, &mut Idm::default(), &config);
            assert!(!clone.collision, "{}: the clone collided", algo.name());
            assert!(
                (clone.route_complete - teacher.route_complete).abs() < 0.05,
                "{}: the clone drove {:.3} of the route, the teacher {:.3}",
                algo.name(),
                clone.route_complete,
                teacher.route_complete
            );
        }
        // the clone is a driver `learned:` reads
        let actor = trainer.actor().expect("the actor");
        assert_eq!(actor.inputs(), Observation::State.width());
    }
}

#[test]
fn a_job_is_a_scene_with_its_parameters() {
    let scene = scene(10, false);
    let fixed = [0.5];
    let job: Job = TrainScene { scene: &scene, fixed: Some((&fixed, 3)) }.job(99);
    assert_eq!((job.params.as_slice(), job.seed), (&fixed[..], 3));
    let sampled = TrainScene { scene: &scene, fixed: None }.job(99);
    assert_eq!((sampled.params, sampled.seed), (params(&scene, 99), 99));
}
