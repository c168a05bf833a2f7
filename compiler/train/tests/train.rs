//! SAC on hand-built straight-road scenes: learning, exact resume, the split, the saved
//! actor, damaged checkpoints. Small networks and short episodes so a debug build runs
//! them in about a minute; the settings' defaults are checked separately.

use std::time::Instant;

use tad_policy::{EgoPolicy, EgoView, Learned};
use tad_train::{Config, Trainer, split};

mod common;

use common::{blocked, mean_return, params, scene, small, temp, train};

#[test]
fn training_improves_the_return_on_two_scenes_with_a_parameter() {
    let scenes = [scene(80, false), scene(80, true)];
    let mut trainer = Trainer::new(small(3)).expect("a trainer");
    let before = mean_return(&trainer, &scenes);
    let started = Instant::now();
    train(&mut trainer, &scenes, 100);
    let elapsed = started.elapsed().as_secs_f64();
    let after = mean_return(&trainer, &scenes);
    eprintln!(
        "return {before:.1} -> {after:.1} after {} episodes, {} updates, {elapsed:.1} s",
        trainer.episodes(),
        trainer.updates()
    );
    assert!(trainer.updates() > 0, "learning started");
    assert!(after > before + 100.0, "return {before:.1} -> {after:.1}");
}

#[test]
fn a_resumed_run_ends_with_the_same_bytes() {
    let scenes = [scene(30, false), scene(30, true)];
    let config = Config { start_training: 40, updates_per_episode: 2, batch: 32, ..small(9) };
    let dir = temp("resume");

    let mut whole = Trainer::new(config.clone()).expect("a trainer");
    train(&mut whole, &scenes, 8);
    whole.save_actor(dir.join("whole.safetensors")).expect("saved");
    whole.save_checkpoint(dir.join("whole.ckpt")).expect("saved");

    let mut first = Trainer::new(config.clone()).expect("a trainer");
    first.set_note("scenes: alone, lead");
    train(&mut first, &scenes, 4);
    assert!(first.updates() > 0, "the first half learns already");
    first.save_checkpoint(dir.join("half.ckpt")).expect("saved");
    drop(first);
    let mut second = Trainer::load_checkpoint(dir.join("half.ckpt")).expect("loaded");
    assert_eq!(second.episodes(), 4);
    assert_eq!(second.note(), "scenes: alone, lead");
    train(&mut second, &scenes, 8);
    second.save_actor(dir.join("resumed.safetensors")).expect("saved");
    second.save_checkpoint(dir.join("resumed.ckpt")).expect("saved");

    let read = |name: &str| std::fs::read(dir.join(name)).expect("written");
    assert_eq!(read("whole.safetensors"), read("resumed.safetensors"), "the actors' bytes");
    for file in ["critics.safetensors", "optimizer.safetensors", "replay.safetensors"] {
        assert_eq!(read(&format!("whole.ckpt/{file}")), read(&format!("resumed.ckpt/{file}")), "{file}");
    }
    assert_eq!(whole.updates(), second.updates());

    // the same seed again: the same bytes; another seed: others
    let mut again = Trainer::new(config.clone()).expect("a trainer");
    train(&mut again, &scenes, 8);
    again.save_actor(dir.join("again.safetensors")).expect("saved");
    assert_eq!(read("whole.safetensors"), read("again.safetensors"));
    let mut other = Trainer::new(Config { seed: 10, ..config }).expect("a trainer");
    train(&mut other, &scenes, 8);
    other.save_actor(dir.join("other.safetensors")).expect("saved");
    assert_ne!(read("whole.safetensors"), read("other.safetensors"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn colliding_steps_are_kept_apart_and_resume_exactly() {
    let scenes = [blocked(40), scene(30, false)];
    let config = Config { start_training: 40, updates_per_episode: 2, batch: 30, collision_share: 0.2, ..small(4) };
    let dir = temp("collisions");
    let mut whole = Trainer::new(config.clone()).expect("a trainer");
    train(&mut whole, &scenes, 10);
    assert!(whole.collisions_len() > 0, "the blocked road's collisions are kept apart");
    assert!(whole.collisions_len() <= config.buffer / 100, "the ring holds 1/100 of the replay");
    whole.save_checkpoint(dir.join("whole.ckpt")).expect("saved");

    let mut first = Trainer::new(config.clone()).expect("a trainer");
    train(&mut first, &scenes, 5);
    first.save_checkpoint(dir.join("half.ckpt")).expect("saved");
    let mut second = Trainer::load_checkpoint(dir.join("half.ckpt")).expect("loaded");
    assert_eq!(second.collisions_len(), first.collisions_len());
    train(&mut second, &scenes, 10);
    second.save_checkpoint(dir.join("resumed.ckpt")).expect("saved");
    let read = |name: &str| std::fs::read(dir.join(name)).expect("written");
    for file in ["actor.safetensors", "critics.safetensors", "replay.safetensors"] {
        assert_eq!(read(&format!("whole.ckpt/{file}")), read(&format!("resumed.ckpt/{file}")), "{file}");
    }

    // one ring, as SafeBench: the same episodes learn otherwise
    let mut one = Trainer::new(Config { collision_share: 0.0, ..config }).expect("a trainer");
    train(&mut one, &scenes, 10);
    assert_eq!(one.collisions_len(), 0);
    one.save_checkpoint(dir.join("one.ckpt")).expect("saved");
    assert_ne!(read("one.ckpt/actor.safetensors"), read("whole.ckpt/actor.safetensors"));

    // a ring that does not fit its capacity is a damaged checkpoint
    let state = std::fs::read_to_string(dir.join("whole.ckpt/state.json")).expect("read");
    std::fs::write(
        dir.join("whole.ckpt/state.json"),
        state.replace("\"collisions_next\": ", "\"collisions_next\": 999"),
    )
    .expect("written");
    let e = Trainer::load_checkpoint(dir.join("whole.ckpt")).err().expect("an error");
    assert!(e.to_string().contains("collisions"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Keeps the views it was shown.
struct Both {
    a: Learned,
    b: Learned,
    differ: usize,
    steps: usize,
}

impl EgoPolicy for Both {
    fn name(&self) -> &str {
        "both"
    }
    fn act(&mut self, view: &EgoView) -> tad_policy::Action {
        let (x, y) = (self.a.act(view), self.b.act(view));
        self.steps += 1;
        if x != y {
            self.differ += 1;
        }
        x
    }
}

#[test]
fn the_saved_actor_loads_as_learned_and_acts_the_same() {
    let scenes = [scene(40, true)];
    let config = Config { start_training: 30, updates_per_episode: 3, batch: 32, ..small(5) };
    let mut trainer = Trainer::new(config.clone()).expect("a trainer");
    train(&mut trainer, &scenes, 3);
    assert!(trainer.updates() > 0);
    let dir = temp("actor");
    let path = dir.join("actor.safetensors");
    trainer.save_actor(&path).expect("saved");
    let loaded = Learned::load(&path).expect("loads as the learned policy");
    let spec = format!("learned:{}", path.display());
    assert!(tad_policy::parse_policy(&spec).is_ok(), "--ego {spec}");
    let actor = trainer.actor().expect("the actor");
    assert_eq!(loaded.hidden(), vec![32, 32]);
    let mut both = Both { a: loaded, b: actor, differ: 0, steps: 0 };
    let scene = &scenes[0];
    let stats = tad_train::evaluate(scene, params(scene, 1), 1, &mut both, &config);
    assert!(both.steps > 10 && both.differ == 0, "{} of {} steps differ", both.differ, both.steps);
    // the trainer's own deterministic episode is the loaded actor's
    let own = trainer.evaluate(scene, params(scene, 1), 1);
    assert_eq!(own, stats);
    // and the checkpoint's actor file is the same actor
    trainer.save_checkpoint(dir.join("ckpt")).expect("saved");
    let from_checkpoint = Learned::load(dir.join("ckpt/actor.safetensors")).expect("loads");
    assert_eq!(from_checkpoint.mu(&[0.3, -0.1, 7.0, 1.0]), trainer.actor().expect("actor").mu(&[0.3, -0.1, 7.0, 1.0]));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_existing_actor_is_fine_tuned() {
    let start = Learned::random(&[16, 24], 4).expect("an actor");
    let mut trainer =
        Trainer::new(Config { start_training: 20, batch: 16, updates_per_episode: 1, ..small(1) }).expect("a trainer");
    trainer.init_actor(&start).expect("takes the actor");
    assert_eq!(trainer.actor().expect("actor").mu(&[0.0, 0.0, 8.0, 0.0]), start.mu(&[0.0, 0.0, 8.0, 0.0]));
    assert_eq!(trainer.actor().expect("actor").hidden(), vec![16, 24]);
    let scenes = [scene(30, false)];
    train(&mut trainer, &scenes, 2);
    assert!(trainer.updates() > 0);
    assert_ne!(trainer.actor().expect("actor").mu(&[0.0, 0.0, 8.0, 0.0]), start.mu(&[0.0, 0.0, 8.0, 0.0]));
}

/// A run's critics written out and read into another run of the same widths: that run
/// trains on from them (its critics end elsewhere than a fresh start's), its targets start
/// as their copies; damaged or mismatched critics are errors.
#[test]
fn critics_go_from_one_run_to_another() {
    let dir = temp("critics");
    let scenes = [scene(30, false)];
    let config = Config { start_training: 20, batch: 16, updates_per_episode: 1, ..small(4) };
    let mut first = Trainer::new(config.clone()).expect("a trainer");
    train(&mut first, &scenes, 3);
    assert!(first.updates() > 0);
    first.critics().expect("critics").save(dir.join("critics.safetensors")).expect("saved");
    let bytes = std::fs::read(dir.join("critics.safetensors")).expect("written");

    // the same start twice, once with the first run's critics
    let start = first.actor().expect("actor");
    let run = |critics: Option<&[u8]>| {
        let mut t = Trainer::new(Config { seed: 11, ..config.clone() }).expect("a trainer");
        t.init_actor(&start).expect("takes the actor");
        if let Some(bytes) = critics {
            t.init_critics(bytes, "critics.safetensors").expect("takes the critics");
        }
        train(&mut t, &scenes, 2);
        t.save_checkpoint(dir.join(if critics.is_some() { "with" } else { "fresh" })).expect("saved");
        t
    };
    let (with, fresh) = (run(Some(&bytes)), run(None));
    assert!(with.updates() > 0 && fresh.updates() > 0);
    let read = |name: &str| std::fs::read(dir.join(name)).expect("written");
    assert_ne!(read("with/critics.safetensors"), read("fresh/critics.safetensors"), "the critics started elsewhere");
    // the targets started as copies of the critics they follow
    let mut again = Trainer::new(Config { seed: 11, ..config.clone() }).expect("a trainer");
    again.init_critics(&bytes, "critics.safetensors").expect("takes the critics");
    again.save_checkpoint(dir.join("again")).expect("saved");
    let saved = candle_core::safetensors::load(dir.join("again/critics.safetensors"), &candle_core::Device::Cpu)
        .expect("a safetensors file");
    for (name, t) in &saved {
        if let Some(trained) = name.strip_prefix("q1_target.").map(|rest| format!("q1.{rest}")) {
            let values = |t: &candle_core::Tensor| t.flatten_all().unwrap().to_vec1::<f32>().unwrap();
            assert_eq!(values(t), values(&saved[&trained]), "{name}");
        }
    }

    let mut err = |bytes: &[u8]| again.init_critics(bytes, "x").expect_err("an error").to_string();
    let garbage = err(b"garbage");
    assert!(garbage.contains("not a safetensors file"), "{garbage}");
    let actor = std::fs::read(dir.join("with/actor.safetensors")).expect("written");
    let swapped = err(&actor);
    assert!(swapped.contains("q1."), "{swapped}");
    let mut wide = Trainer::new(Config { hidden: vec![8], ..config.clone() }).expect("a trainer");
    assert!(wide.init_critics(&bytes, "x").is_err(), "other widths");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_split_keeps_three_fifths_of_each_behaviour() {
    let mut keys = Vec::new();
    for (key, n) in [("cut_in", 10), ("crossing", 5), ("pair", 2), ("single", 1), ("three", 3), ("four", 4)] {
        keys.extend((0..n).map(|_| key.to_string()));
    }
    let (train, test) = split(&keys, 7);
    assert_eq!(train.len() + test.len(), keys.len());
    let count = |list: &[usize], key: &str| list.iter().filter(|&&i| keys[i] == key).count();
    for (key, expected) in [("cut_in", 6), ("crossing", 3), ("pair", 1), ("single", 1), ("three", 2), ("four", 2)] {
        assert_eq!(count(&train, key), expected, "{key}");
    }
    let mut all: Vec<usize> = train.iter().chain(&test).copied().collect();
    all.sort_unstable();
    assert_eq!(all, (0..keys.len()).collect::<Vec<_>>(), "every item once");
    assert_eq!(split(&keys, 7), (train.clone(), test.clone()), "seeded");
    let others: Vec<_> = (0..20).map(|s| split(&keys, s).0).collect();
    assert!(others.iter().any(|t| *t != train), "another seed, another split");
    // another key's items change nothing in this key's split
    let mut more = keys.clone();
    more.extend((0..4).map(|_| "extra".to_string()));
    let (train_more, _) = split(&more, 7);
    assert!(train.iter().all(|i| train_more.contains(i)));
    assert_eq!(split(&[], 1), (vec![], vec![]));
}

#[test]
fn a_damaged_checkpoint_is_an_error() {
    let dir = temp("damaged");
    let scenes = [scene(20, false)];
    let mut trainer = Trainer::new(Config { start_training: 10, batch: 8, ..small(2) }).expect("a trainer");
    train(&mut trainer, &scenes, 1);
    let good = dir.join("good");
    trainer.save_checkpoint(&good).expect("saved");
    assert!(Trainer::load_checkpoint(&good).is_ok());
    assert!(!dir.join("good.part").exists(), "no partial directory is left");

    let missing = Trainer::load_checkpoint(dir.join("nowhere")).err().expect("an error");
    assert!(missing.to_string().contains("state.json"), "{missing}");

    let damage = |name: &str, file: &str, bytes: &[u8]| {
        let copy = dir.join(name);
        std::fs::create_dir_all(&copy).expect("a directory");
        for entry in std::fs::read_dir(&good).expect("listed") {
            let entry = entry.expect("an entry");
            std::fs::copy(entry.path(), copy.join(entry.file_name())).expect("copied");
        }
        std::fs::write(copy.join(file), bytes).expect("written");
        Trainer::load_checkpoint(&copy).err().unwrap_or_else(|| panic!("{name}: loaded"))
    };
    let e = damage("json", "state.json", b"{ not json");
    assert!(e.to_string().contains("not a usable checkpoint"), "{e}");
    damage("actor", "actor.safetensors", b"garbage");
    damage("critics", "critics.safetensors", b"");
    damage("optimizer", "optimizer.safetensors", &[0u8; 64]);
    damage("replay", "replay.safetensors", b"\x08\x00\x00\x00\x00\x00\x00\x00{}      ");
    // a real safetensors file of the wrong contents
    let other = std::fs::read(good.join("actor.safetensors")).expect("read");
    let e = damage("swapped", "critics.safetensors", &other);
    assert!(e.to_string().contains("q1."), "{e}");
    let state = std::fs::read_to_string(good.join("state.json")).expect("read");
    damage("format", "state.json", state.replace("checkpoint 2", "checkpoint 9").as_bytes());
    damage("widths", "state.json", state.replacen("32", "33", 1).as_bytes());
    damage("position", "state.json", state.replace("\"replay_next\": ", "\"replay_next\": 9999").as_bytes());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_settings_are_errors() {
    for config in [
        Config { hidden: vec![], ..Config::default() },
        Config { hidden: vec![8, 0], ..Config::default() },
        Config { actor_lr: 0.0, ..Config::default() },
        Config { critic_lr: f64::NAN, ..Config::default() },
        Config { gamma: 1.5, ..Config::default() },
        Config { batch: 0, ..Config::default() },
        Config { desired_speed: Some(-1.0), ..Config::default() },
        Config { collision_share: 1.5, ..Config::default() },
    ] {
        assert!(Trainer::new(config.clone()).is_err(), "{config:?}");
    }
    let d = Config::default();
    assert_eq!((d.hidden.clone(), d.actor_lr, d.critic_lr, d.alpha), (vec![256, 256], 1e-4, 1e-4, 0.01));
    assert_eq!((d.gamma, d.polyak, d.batch, d.buffer, d.start_training), (0.99, 0.995, 512, 30_000, 1000));
    assert_eq!((d.episodes, d.updates_per_episode), (600, 1));
}

/// Figures for the record (run with `--ignored --nocapture`): ms per episode and per update
/// at ChatScene's sizes.
#[test]
#[ignore]
fn timings() {
    let scenes = [scene(300, true)];
    let mut trainer =
        Trainer::new(Config { start_training: 1, updates_per_episode: 0, ..Config::default() }).expect("a trainer");
    let t = Instant::now();
    let mut steps = 0;
    for seed in 0..5 {
        steps += trainer.step(&scenes[0], params(&scenes[0], seed), seed).expect("an episode").steps;
    }
    let per_episode = t.elapsed().as_secs_f64() * 1e3 / 5.0;
    let t = Instant::now();
    for _ in 0..5 {
        trainer.update().expect("an update");
    }
    let per_update = t.elapsed().as_secs_f64() * 1e3 / 5.0;
    eprintln!("{per_episode:.1} ms per episode ({} steps), {per_update:.1} ms per update at batch 512", steps / 5);
}
