//! SAC on the runtime: training improves a learned ego's return on a tiny scenario set
//! (seeded), a resumed run is the unbroken one, the split, the saved actor drives as
//! `learned:PATH`, and damaged checkpoints are errors.

mod common;

use common::temp;
use tad_policy::{EgoPolicy, Learned};
use tad_runtime::Scene;
use tad_train::{Config, TrainError, Trainer, split};

/// The ego alone on a straight road: the return rewards driving along the route at the
/// stated speed, straight.
const ALONE: &str = "scenario alone {
  environment {
    weather: clear
    time: daytime
  }
  road {
    type: straight_road
    context: urban
    lanes: 2
    direction: two_way
    light: none
  }
  ego {
    behavior: move_forward
    speed: 30 km/h
    lane: 1
  }
}
";

fn scene(src: &str) -> Scene {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file("alone.tad".into(), src.to_string());
    let scenario = tad_db::resolve(&db, file).clone().expect("a scenario");
    let layout = tad_layout::lay_out(&scenario);
    Scene::new(&tad_bytecode::lower(&scenario, &layout, "alone.tad")).expect("it sets up")
}

/// Small networks and many updates per episode, so a few dozen episodes learn.
fn small(seed: u64) -> Config {
    Config {
        hidden: vec![32, 32],
        actor_lr: 1e-3,
        critic_lr: 1e-3,
        batch: 64,
        start_training: 200,
        updates_per_episode: 20,
        seed,
        ..Config::default()
    }
}

fn mean_return(trainer: &Trainer, scene: &Scene) -> f64 {
    (0..3).map(|s| trainer.evaluate(scene, Vec::new(), s).episode_return).sum::<f64>() / 3.0
}

#[test]
fn training_improves_the_return() {
    let scene = scene(ALONE);
    let mut trainer = Trainer::new(small(1)).unwrap();
    let before = mean_return(&trainer, &scene);
    // 60 episodes: at 30, 4 of 10 seeds had not yet improved; at 60 all 10 had, by 150 or more
    for _ in 0..60 {
        let task = trainer.task(1);
        trainer.step(&scene, Vec::new(), task.seed).unwrap();
    }
    assert!(trainer.updates() > 0);
    let after = mean_return(&trainer, &scene);
    assert!(after > before + 100.0, "return {before:.1} before training, {after:.1} after");
}

#[test]
fn a_resumed_run_is_the_unbroken_run() {
    let scene = scene(ALONE);
    let config = Config { start_training: 50, updates_per_episode: 2, ..small(7) };
    let dir = temp("resume");
    let mut whole = Trainer::new(config.clone()).unwrap();
    for _ in 0..4 {
        let t = whole.task(1);
        whole.step(&scene, Vec::new(), t.seed).unwrap();
    }
    let mut first = Trainer::new(config).unwrap();
    for _ in 0..2 {
        let t = first.task(1);
        first.step(&scene, Vec::new(), t.seed).unwrap();
    }
    first.save_checkpoint(dir.join("ckpt")).unwrap();
    let mut resumed = Trainer::load_checkpoint(dir.join("ckpt")).unwrap();
    assert_eq!(resumed.episodes(), 2);
    for _ in 0..2 {
        let t = resumed.task(1);
        resumed.step(&scene, Vec::new(), t.seed).unwrap();
    }
    assert!(whole.updates() > 0);
    whole.save_actor(dir.join("whole.safetensors")).unwrap();
    resumed.save_actor(dir.join("resumed.safetensors")).unwrap();
    assert_eq!(
        std::fs::read(dir.join("whole.safetensors")).unwrap(),
        std::fs::read(dir.join("resumed.safetensors")).unwrap(),
        "the same actor bytes"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_saved_actor_drives_as_learned() {
    let scene = scene(ALONE);
    let trainer = Trainer::new(small(3)).unwrap();
    let path = temp("actor").join("actor.safetensors");
    trainer.save_actor(&path).unwrap();
    let mut loaded = tad_policy::parse_policy(&format!("learned:{}", path.display())).unwrap();
    let mut own = trainer.actor().unwrap();
    let a = tad_runtime::run(&scene, Some(0), Vec::new(), loaded.as_mut(), &Default::default());
    let b = tad_runtime::run(&scene, Some(0), Vec::new(), &mut own as &mut dyn EgoPolicy, &Default::default());
    assert_eq!(a.records, b.records);
    assert_eq!(Learned::load(&path).unwrap().hidden(), vec![32, 32]);
    let _ = std::fs::remove_file(&path);
}

#[test]
fn split_keeps_three_fifths_of_each_behaviour() {
    let keys: Vec<String> =
        ["cut_in"; 5].into_iter().chain(["crossing"; 10]).chain(["alone"]).map(String::from).collect();
    let (train, test) = split(&keys, 4);
    let count = |list: &[usize], key: &str| list.iter().filter(|&&i| keys[i] == key).count();
    assert_eq!((count(&train, "cut_in"), count(&test, "cut_in")), (3, 2));
    assert_eq!((count(&train, "crossing"), count(&test, "crossing")), (6, 4));
    assert_eq!((count(&train, "alone"), count(&test, "alone")), (1, 0));
    assert_eq!(split(&keys, 4), (train.clone(), test.clone()));
    assert_ne!(split(&keys, 5).0, train);
}

#[test]
fn damaged_checkpoints_and_settings_are_errors() {
    let dir = temp("bad").join("checkpoint");
    assert!(matches!(Trainer::load_checkpoint(&dir), Err(TrainError::Io { .. })));
    let trainer = Trainer::new(small(2)).unwrap();
    trainer.save_checkpoint(&dir).unwrap();
    std::fs::write(dir.join("state.json"), "{\"format\": 3}").unwrap();
    assert!(matches!(Trainer::load_checkpoint(&dir), Err(TrainError::Checkpoint { .. })));
    trainer.save_checkpoint(&dir).unwrap();
    std::fs::write(dir.join("critics.safetensors"), b"not tensors").unwrap();
    assert!(matches!(Trainer::load_checkpoint(&dir), Err(TrainError::Checkpoint { .. })));
    trainer.save_checkpoint(&dir).unwrap();
    std::fs::remove_file(dir.join("replay.safetensors")).unwrap();
    assert!(Trainer::load_checkpoint(&dir).is_err());
    assert!(matches!(Trainer::new(Config { hidden: vec![], ..Config::default() }), Err(TrainError::Config(_))));
    assert!(matches!(Trainer::new(Config { actor_lr: f64::NAN, ..Config::default() }), Err(TrainError::Config(_))));
    let _ = std::fs::remove_dir_all(&dir);
}
