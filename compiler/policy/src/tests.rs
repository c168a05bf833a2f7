//! The drivers in closed loop on a straight lane (a point mass, exact IDM numbers), pure
//! pursuit's sign, the observation's signs, and the learned actor's file round trip
//! against a hand-computed forward pass.

use super::*;
use candle_core::{Device, Tensor};
use std::collections::HashMap;
use std::path::PathBuf;
use tad_ir::{Rng, SplitMix64};

fn view(speed: f64, desired_speed: f64) -> EgoView {
    EgoView {
        obs: [0.0, 0.0, speed, 0.0],
        speed,
        desired_speed,
        target: [8.0, 0.0],
        lookahead: 8.0,
        wheelbase: 2.9,
        leader: None,
        stop: None,
        curve_speed: f64::INFINITY,
        dt: 0.1,
        around: [None; NEAR],
    }
}

/// Drive `policy` along a straight lane for `seconds` from `speed`, with something at
/// `obstacle` m ahead (its front bumper; `None`: nothing) moving at `obstacle_speed`,
/// shown as a leader or as a stop point. Returns (final speed, least gap, final gap,
/// greatest speed).
fn drive(
    policy: &mut dyn EgoPolicy,
    speed: f64,
    desired: f64,
    obstacle: Option<(f64, f64)>,
    as_stop: bool,
    seconds: f64,
) -> (f64, f64, f64, f64) {
    let dt = 0.1;
    let (mut v, mut x) = (speed, 0.0);
    let (mut least, mut gap, mut fastest) = (f64::INFINITY, f64::INFINITY, v);
    policy.reset();
    for step in 0..(seconds / dt) as usize {
        let t = step as f64 * dt;
        let mut s = view(v, desired);
        if let Some((at, lead)) = obstacle {
            gap = at + lead * t - x;
            least = least.min(gap);
            if as_stop { s.stop = Some(gap) } else { s.leader = Some((gap, lead)) }
        }
        let a = policy.act(&s);
        assert!(a.accel.is_finite() && (ACCEL_MIN..=ACCEL_MAX).contains(&a.accel), "{a:?}");
        v = (v + a.accel * dt).max(0.0);
        x += v * dt;
        fastest = fastest.max(v);
    }
    (v, least, gap, fastest)
}

#[test]
fn idm_stops_before_a_standing_leader() {
    // From 10 m/s, a standing car 50 m ahead: IDM stops about s0 = 2 m behind it.
    let (v, least, last, _) = drive(&mut Idm::default(), 10.0, 10.0, Some((50.0, 0.0)), false, 60.0);
    assert!(v < STANDING, "still moving at {v}");
    assert!(least > 1.95 && last < 2.05, "least gap {least}, final gap {last}");
}

#[test]
fn idm_stops_at_a_red_light() {
    // The same as a stop point (a red light's line 30 m ahead, from 12 m/s).
    let (v, least, last, _) = drive(&mut Idm::default(), 12.0, 12.0, Some((30.0, 0.0)), true, 60.0);
    assert!(v < STANDING && least > 1.95 && last < 2.05, "speed {v}, least {least}, final {last}");
    // A stop cleared (the runtime's stop sign once served): it drives off again.
    assert!(Idm::default().act(&view(0.0, 10.0)).accel > 1.9);
}

#[test]
fn idm_reaches_the_desired_speed() {
    // Free road from rest: 1 − (v/v0)⁴ vanishes only at v0, never beyond it.
    let (v, _, _, fastest) = drive(&mut Idm::default(), 0.0, 10.0, None, false, 60.0);
    assert!(v > 9.9 && fastest <= 10.0, "speed {v}, fastest {fastest}");
}

#[test]
fn idm_follows_at_the_equilibrium_gap() {
    // Behind a leader at 5 m/s (v0 10): steady state at v = 5 with
    // s = (s0 + vT) / √(1 − (v/v0)⁴) = (2 + 7.5) / √(15/16) = 9.812 m.
    let (v, _, gap, _) = drive(&mut Idm::default(), 5.0, 10.0, Some((30.0, 5.0)), false, 200.0);
    assert!((v - 5.0).abs() < 0.01, "speed {v}");
    assert!((gap - 9.5 / (15.0f64 / 16.0).sqrt()).abs() < 0.05, "gap {gap}");
}

#[test]
fn idm_brakes_hard_when_close() {
    // 15 m/s with a standing car 5 m ahead: s* = 2 + 22.5 + 15·15/(2√6) ≈ 70 m, far more
    // than the gap: the hardest braking.
    let mut s = view(15.0, 15.0);
    s.leader = Some((5.0, 0.0));
    assert_eq!(Idm::default().act(&s).accel, -8.0);
    // Standing still behind it, it does not reverse.
    let mut s = view(0.0, 15.0);
    s.leader = Some((1.0, 0.0));
    assert_eq!(Idm::default().act(&s).accel, 0.0);
}

#[test]
fn pure_pursuit_steers_towards_the_target() {
    // Target 10 m ahead, 2 m left, wheelbase 2.7: κ = 2·2/104, wheel angle
    // atan(2.7·4/104) = 0.103483 rad; CARLA's sign: −0.103483 / (70° = 1.221730 rad).
    assert!((pure_pursuit([10.0, 2.0], 2.7) - (-0.103483 / 1.221730)).abs() < 1e-5);
    assert!(pure_pursuit([10.0, -2.0], 2.7) > 0.0);
    assert_eq!(pure_pursuit([10.0, 0.0], 2.7), 0.0);
    assert_eq!(pure_pursuit([0.0, 0.0], 2.7), 0.0);
    // A target beside the car: the tightest arc, clamped.
    assert_eq!(pure_pursuit([0.1, 0.5], 2.7), -1.0);
    let mut s = view(5.0, 5.0);
    s.target = [6.0, 1.5];
    assert!(Idm::default().act(&s).steer < 0.0);
    assert!(Naive::default().act(&s).steer < 0.0);
}

#[test]
fn naive_ignores_leaders_and_lights() {
    // Holds its 8 m/s through a standing car and a red light.
    for as_stop in [false, true] {
        let (v, least, _, _) = drive(&mut Naive::default(), 8.0, 12.0, Some((20.0, 0.0)), as_stop, 10.0);
        assert!((v - 8.0).abs() < 1e-9 && least < 0.0, "speed {v}, least gap {least}");
    }
    // From rest it takes the desired speed, reached at IDM's comfortable 2 m/s².
    let mut naive = Naive::default();
    assert_eq!(naive.act(&view(0.0, 6.0)).accel, 2.0);
    assert_eq!(naive.hold(), Some(6.0));
    assert_eq!(naive.act(&view(7.0, 6.0)).accel, -3.0);
    naive.reset();
    assert_eq!(naive.hold(), None);
    let (v, _, _, _) = drive(&mut naive, 0.0, 6.0, None, false, 10.0);
    assert!((v - 6.0).abs() < 1e-9, "speed {v}");
}

#[test]
fn observation_signs() {
    // Route along +x; the ego 1 m to its left heading 10° left: both positive.
    let [lateral, angle, speed] = observation([3.0, 1.0], 10f64.to_radians(), [5.0, 0.0], 0.0, -4.0);
    assert!((lateral - 1.0).abs() < 1e-12);
    assert!((angle - 10f64.to_radians()).abs() < 1e-12);
    assert_eq!(speed, 4.0);
    // Route heading north (+y), the ego east of it (to its right) heading north-east.
    let [lateral, angle, _] = observation([2.0, 0.0], 45f64.to_radians(), [0.0, 5.0], 90f64.to_radians(), 1.0);
    assert!((lateral + 2.0).abs() < 1e-12);
    assert!((angle + 45f64.to_radians()).abs() < 1e-12);
}

#[test]
fn preview_advances_as_safebench_purges() {
    // Points 1 m apart on the x axis. At x = 0 the head is 0: the preview is P_2; points
    // within 4 m go up to P_3, so the head moves to 2. At x = 0.5 the preview is P_4;
    // reached up to P_4 (3.5 m): head 3. Going back never moves the head back.
    let points: Vec<[f64; 2]> = (0..30).map(|k| [k as f64, 0.0]).collect();
    let mut p = Preview::default();
    assert_eq!(p.step(&points, [0.0, 0.0]), Some(2));
    assert_eq!(p.head, 2);
    assert_eq!(p.step(&points, [0.5, 0.0]), Some(4));
    assert_eq!(p.head, 3);
    assert_eq!(p.step(&points, [-10.0, 0.0]), Some(5));
    assert_eq!(p.head, 3);
    // Near the end the preview is the last point; no points, no preview.
    let mut p = Preview { head: 28 };
    assert_eq!(p.step(&points, [28.0, 0.0]), Some(29));
    assert_eq!(Preview::default().step(&[], [0.0, 0.0]), None);
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tad-policy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn tensor(values: &[f32], shape: &[usize]) -> Tensor {
    Tensor::from_vec(values.to_vec(), shape, &Device::Cpu).unwrap()
}

/// A tiny actor, 4 → 3 → 2, with round weights, as SafeBench names them.
fn tiny() -> HashMap<String, Tensor> {
    HashMap::from([
        ("fc1.weight".to_string(), tensor(&[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.5, -1.0], &[3, 4])),
        ("fc1.bias".to_string(), tensor(&[0.0, 0.5, 0.0], &[3])),
        ("fc_mu.weight".to_string(), tensor(&[1.0, 2.0, -1.0, 0.5, 0.0, 0.25], &[2, 3])),
        ("fc_mu.bias".to_string(), tensor(&[0.1, -0.2], &[2])),
        ("fc_std.weight".to_string(), tensor(&[0.0; 6], &[2, 3])),
        ("fc_std.bias".to_string(), tensor(&[0.0; 2], &[2])),
    ])
}

#[test]
fn learned_matches_a_hand_computed_forward_pass() {
    // obs [0.5, −1, 4, 1]: fc1 = [0.5, −1 + 0.5, 0.5·4 − 1] = [0.5, −0.5, 1], relu [0.5, 0, 1];
    // fc_mu = [0.5 + 0 − 1 + 0.1, 0.25 + 0 + 0.25 − 0.2] = [−0.4, 0.3];
    // braking: accel = 8·tanh(−0.4) = −3.039592, steer = 0.3·tanh(0.3) = 0.087394.
    let path = temp("tiny.safetensors");
    candle_core::safetensors::save(&tiny(), &path).unwrap();
    let mut actor = Learned::load(&path).unwrap();
    assert_eq!(actor.hidden(), [3]);
    assert_eq!(actor.name(), format!("learned:{}", path.display()));
    let mut s = view(4.0, 8.0);
    s.obs = [0.5, -1.0, 4.0, 1.0];
    let a = actor.act(&s);
    assert!((a.accel - 8.0 * (-0.4f64).tanh()).abs() < 1e-5, "{a:?}");
    assert!((a.steer - 0.3 * 0.3f64.tanh()).abs() < 1e-5, "{a:?}");
    assert!((a.accel + 3.039592).abs() < 1e-5 && (a.steer - 0.087394).abs() < 1e-5);
    // Named as a whole checkpoint flattened, in f64, without the std head: the same.
    let prefixed: HashMap<String, Tensor> = tiny()
        .into_iter()
        .filter(|(k, _)| !k.starts_with("fc_std"))
        .map(|(k, t)| (format!("policy_net.{k}"), t.to_dtype(candle_core::DType::F64).unwrap()))
        .collect();
    let path = temp("prefixed.safetensors");
    candle_core::safetensors::save(&prefixed, &path).unwrap();
    assert_eq!(Learned::load(&path).unwrap().act(&s), a);
}

#[test]
fn learned_random_round_trip() {
    let actor = Learned::random(&[64, 256], 7).unwrap();
    assert_eq!(actor.hidden(), [64, 256]);
    let path = temp("random.safetensors");
    actor.save(&path).unwrap();
    let mut loaded = parse_policy(&format!("learned:{}", path.display())).unwrap();
    let mut original = actor.clone();
    for obs in [[0.0, 0.0, 0.0, 0.0], [1.5, -0.3, 8.0, 1.0], [-2.0, 1.0, 30.0, 0.0], [40.0, -40.0, 200.0, 1.0]] {
        let mut s = view(obs[2], 8.0);
        s.obs = obs;
        let a = loaded.act(&s);
        assert_eq!(a, loaded.act(&s), "deterministic");
        assert_eq!(a, original.act(&s), "the file holds the actor");
        assert!((-8.0..=3.0).contains(&a.accel) && a.steer.abs() <= 0.3, "{a:?}");
    }
    // The seed decides the weights.
    let again = temp("again.safetensors");
    Learned::random(&[64, 256], 7).unwrap().save(&again).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), std::fs::read(&again).unwrap());
    let other = Learned::random(&[64, 256], 8).unwrap();
    assert_ne!(other.mu(&[1.0, 0.5, 5.0, 0.0]), actor.mu(&[1.0, 0.5, 5.0, 0.0]));
    assert!(matches!(Learned::random(&[], 1), Err(PolicyError::BadHidden { .. })));
    assert!(matches!(Learned::random(&[4, 0], 1), Err(PolicyError::BadHidden { .. })));
}

#[test]
fn learned_bad_files_are_errors() {
    let missing = temp("missing.safetensors");
    let err = Learned::load(&missing).unwrap_err();
    assert!(matches!(err, PolicyError::Io { .. }), "{err}");
    assert!(err.to_string().starts_with(&missing.display().to_string()));

    let corrupt = temp("corrupt.safetensors");
    std::fs::write(&corrupt, b"\x10\x00\x00\x00\x00\x00\x00\x00{not json at all").unwrap();
    let err = Learned::load(&corrupt).unwrap_err();
    assert!(matches!(err, PolicyError::NotSafetensors { .. }), "{err}");
    assert!(err.to_string().contains("not a safetensors file"), "{err}");

    // A good file cut short.
    let good = temp("good.safetensors");
    candle_core::safetensors::save(&tiny(), &good).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    for cut in [0, 4, 8, 20, bytes.len() / 2, bytes.len() - 1] {
        let truncated = temp("truncated.safetensors");
        std::fs::write(&truncated, &bytes[..cut]).unwrap();
        assert!(matches!(Learned::load(&truncated), Err(PolicyError::NotSafetensors { .. })), "cut at {cut}");
    }

    let mut t = tiny();
    t.remove("fc_mu.bias");
    let err = Learned::from_tensors(&t, "x").unwrap_err();
    assert!(matches!(&err, PolicyError::MissingTensor { name, .. } if name == "fc_mu.bias"), "{err}");

    let mut t = tiny();
    t.insert("fc1.weight".to_string(), tensor(&[0.0; 15], &[3, 5]));
    let err = Learned::from_tensors(&t, "x").unwrap_err();
    assert_eq!(
        err.to_string(),
        "x: tensor `fc1.weight` has shape [3, 5], expected [n, 4] or [n, 13] or [n, 67] (the observation's length)"
    );

    let mut t = tiny();
    t.insert("fc_mu.weight".to_string(), tensor(&[0.0; 8], &[2, 4]));
    assert!(matches!(Learned::from_tensors(&t, "x"), Err(PolicyError::WrongShape { .. })));

    let mut t = tiny();
    t.insert("fc1.bias".to_string(), tensor(&[0.0, f32::NAN, 0.0], &[3]));
    assert!(matches!(Learned::from_tensors(&t, "x"), Err(PolicyError::NonFinite { .. })));

    let other = HashMap::from([("net.0.weight".to_string(), tensor(&[0.0; 4], &[1, 4]))]);
    let err = Learned::from_tensors(&other, "x").unwrap_err();
    assert_eq!(
        err.to_string(),
        "x: no tensor `fc1.weight` (an actor needs SafeBench's `fc1` … `fcN` and `fc_mu`, or an SB3 policy's; found net.0.weight)"
    );
}

#[test]
fn policies_by_name() {
    assert_eq!(parse_policy("idm").unwrap().name(), "idm");
    assert_eq!(parse_policy("naive").unwrap().name(), "naive");
    for model in ["ppo", "sac", "td3"] {
        assert_eq!(parse_policy(model).unwrap().name(), model);
    }
    for bad in ["IDM", "mobil", "", "idm:x"] {
        let err = parse_policy(bad).err().unwrap();
        assert_eq!(
            err.to_string(),
            format!(
                "unknown policy `{bad}` (expected `idm`, `naive`, `ppo`, `sac`, `td3`, `learned:PATH` or `external:CMD`)"
            )
        );
    }
    assert_eq!(parse_policy("learned").err(), Some(PolicyError::MissingPath));
    assert_eq!(parse_policy("external: ").err(), Some(PolicyError::MissingCommand));
    assert_eq!(parse_policy("external:./drive --fast").unwrap().name(), "external:./drive --fast");
    assert_eq!(
        crate::split_specs("idm,learned:a.st,external:drive --lanes 1,2"),
        ["idm", "learned:a.st", "external:drive --lanes 1,2"]
    );
    assert_eq!(parse_policy("learned:").err(), Some(PolicyError::MissingPath));
    assert!(matches!(parse_policy("learned:/no/such/file").err(), Some(PolicyError::Io { .. })));
}

#[test]
fn learned_forward_agrees_with_candle() {
    // The same actor through candle-nn's Linear, ReLU and tanh.
    use candle_nn::{Linear, Module};
    let actor = Learned::random(&[64, 256], 11).unwrap();
    let t = actor.tensors().unwrap();
    let linear =
        |name: &str| Linear::new(t[&format!("{name}.weight")].clone(), Some(t[&format!("{name}.bias")].clone()));
    for obs in [[0.3, -0.2, 6.0, 0.0], [-1.7, 0.9, 12.5, 1.0], [0.0; 4]] {
        let input: Vec<f32> = obs.iter().map(|&v| v as f32).collect();
        let mut x = Tensor::from_vec(input, (1, 4), &Device::Cpu).unwrap();
        for name in ["fc1", "fc2"] {
            x = linear(name).forward(&x).unwrap().relu().unwrap();
        }
        let mu = linear("fc_mu").forward(&x).unwrap().tanh().unwrap().flatten_all().unwrap().to_vec1::<f32>().unwrap();
        let ours = actor.mu(&obs);
        assert!((ours[0] - mu[0]).abs() < 1e-5 && (ours[1] - mu[1]).abs() < 1e-5, "{ours:?} vs {mu:?}");
    }
}

/// Seeded values in ±0.5 of `shape`.
fn seeded(shape: &[usize], seed: u64) -> Tensor {
    let mut rng = SplitMix64::new(seed);
    let n = shape.iter().product();
    let values: Vec<f32> = (0..n).map(|_| (rng.unit() - 0.5) as f32).collect();
    Tensor::from_vec(values, shape, &Device::Cpu).unwrap()
}

/// An SB3 `nn.Sequential` of linear layers `widths[0] → widths[1] → …` at `base.0`,
/// `base.2`, …, into `t`.
fn stack(t: &mut HashMap<String, Tensor>, base: &str, widths: &[usize], seed: u64) {
    for (k, w) in widths.windows(2).enumerate() {
        t.insert(format!("{base}.{}.weight", 2 * k), seeded(&[w[1], w[0]], seed + 2 * k as u64));
        t.insert(format!("{base}.{}.bias", 2 * k), seeded(&[w[1]], seed + 2 * k as u64 + 1));
    }
}

/// `x` through the linear layers `names` of `t` (candle-nn), `act` between them.
fn candle_forward(t: &HashMap<String, Tensor>, names: &[String], x: &[f64], act: fn(&Tensor) -> Tensor) -> Vec<f32> {
    use candle_nn::{Linear, Module};
    let input: Vec<f32> = x.iter().map(|&v| v as f32).collect();
    let mut x = Tensor::from_vec(input.clone(), (1, input.len()), &Device::Cpu).unwrap();
    for (k, name) in names.iter().enumerate() {
        let linear = Linear::new(t[&format!("{name}.weight")].clone(), Some(t[&format!("{name}.bias")].clone()));
        x = linear.forward(&x).unwrap();
        if k + 1 < names.len() {
            x = act(&x);
        }
    }
    x.flatten_all().unwrap().to_vec1::<f32>().unwrap()
}

#[test]
fn sb3_policies_load_and_agree_with_candle() {
    use crate::{Format, STATE_DIM};
    let relu = |x: &Tensor| x.relu().unwrap();
    let tanh = |x: &Tensor| x.tanh().unwrap();
    let obs4 = [0.4, -0.3, 7.5, 1.0];
    let state: Vec<f64> = (0..STATE_DIM).map(|k| k as f64 * 0.37 - 2.0).collect();
    let names = |base: &str, n: usize| -> Vec<String> { (0..n).map(|k| format!("{base}.{}", 2 * k)).collect() };

    // PPO on the `state` observation: tanh hidden layers, the mean clipped (big weights
    // make it leave [−1, 1])
    let mut t = HashMap::new();
    stack(&mut t, "mlp_extractor.policy_net", &[STATE_DIM, 64, 64], 1);
    stack(&mut t, "mlp_extractor.value_net", &[STATE_DIM, 64, 64], 9);
    t.insert("action_net.weight".into(), (seeded(&[2, 64], 20) * 8.0).unwrap());
    t.insert("action_net.bias".into(), seeded(&[2], 21));
    t.insert("log_std".into(), seeded(&[2], 22));
    let ppo = Learned::from_tensors(&t, "ppo").unwrap();
    assert_eq!((ppo.format(), ppo.inputs(), ppo.hidden()), (Format::Sb3Ppo, STATE_DIM, vec![64, 64]));
    let mut layers = names("mlp_extractor.policy_net", 2);
    layers.push("action_net".into());
    let mut want = candle_forward(&t, &layers, &state, tanh);
    // the last hidden layer's tanh: candle_forward applies `act` between layers only
    assert_eq!(want.len(), 2);
    want.iter_mut().for_each(|v| *v = v.clamp(-1.0, 1.0));
    let ours = ppo.mu(&state);
    assert!(ours.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-5), "{ours:?} vs {want:?}");
    assert!(ours.iter().any(|v| v.abs() == 1.0), "the test's mean should need clipping: {ours:?}");

    // SAC: ReLU hidden layers, tanh(mu)
    let mut t = HashMap::new();
    stack(&mut t, "actor.latent_pi", &[4, 32, 32], 30);
    t.insert("actor.mu.weight".into(), seeded(&[2, 32], 40));
    t.insert("actor.mu.bias".into(), seeded(&[2], 41));
    t.insert("actor.log_std.weight".into(), seeded(&[2, 32], 42));
    t.insert("actor.log_std.bias".into(), seeded(&[2], 43));
    let sac = Learned::from_tensors(&t, "sac").unwrap();
    assert_eq!((sac.format(), sac.inputs()), (Format::Sb3Sac, 4));
    let mut layers = names("actor.latent_pi", 2);
    layers.push("actor.mu".into());
    let want: Vec<f32> = candle_forward(&t, &layers, &obs4, relu).iter().map(|v| v.tanh()).collect();
    let ours = sac.mu(&obs4);
    assert!(ours.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-5), "{ours:?} vs {want:?}");

    // TD3: one stack, tanh after the last layer
    let mut t = HashMap::new();
    stack(&mut t, "actor.mu", &[4, 16, 16, 2], 50);
    stack(&mut t, "actor_target.mu", &[4, 16, 16, 2], 60);
    let td3 = Learned::from_tensors(&t, "td3").unwrap();
    assert_eq!((td3.format(), td3.hidden()), (Format::Sb3Td3, vec![16, 16]));
    let want: Vec<f32> = candle_forward(&t, &names("actor.mu", 3), &obs4, relu).iter().map(|v| v.tanh()).collect();
    let ours = td3.mu(&obs4);
    assert!(ours.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-5), "{ours:?} vs {want:?}");
    // an SB3 policy is not written back under SafeBench's names
    assert!(td3.tensors().is_err());

    // a file's metadata may name the activation; an unknown one is an error
    let path = temp("td3.safetensors");
    let write = |activation: &str| {
        let meta = HashMap::from([("activation".to_string(), activation.to_string())]);
        let views: Vec<(String, Tensor)> = t.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
        let data: Vec<(String, Vec<u8>, Vec<usize>)> = views
            .iter()
            .map(|(k, v)| {
                let bytes =
                    v.flatten_all().unwrap().to_vec1::<f32>().unwrap().iter().flat_map(|f| f.to_le_bytes()).collect();
                (k.clone(), bytes, v.dims().to_vec())
            })
            .collect();
        let tensors = data.iter().map(|(k, b, s)| {
            (k.clone(), safetensors::tensor::TensorView::new(safetensors::Dtype::F32, s.clone(), b).unwrap())
        });
        safetensors::serialize_to_file(tensors, Some(meta), &path).unwrap();
    };
    write("tanh");
    let loaded = Learned::load(&path).unwrap();
    let want: Vec<f32> = candle_forward(&t, &names("actor.mu", 3), &obs4, tanh).iter().map(|v| v.tanh()).collect();
    let ours = loaded.mu(&obs4);
    assert!(ours.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-5), "{ours:?} vs {want:?}");
    write("gelu");
    let err = Learned::load(&path).unwrap_err().to_string();
    assert!(err.contains("metadata `activation` is `gelu`"), "{err}");
}

#[test]
fn unit_actions_round_trip_through_the_ranges() {
    for unit in [[1.0f32, 1.0], [-1.0, -1.0], [0.5, -0.25], [-0.375, 0.0], [0.0, 0.0]] {
        let action = Action::from_unit(unit);
        let back = action.to_unit();
        assert!(
            (back[0] - unit[0]).abs() < 1e-6 && (back[1] - unit[1]).abs() < 1e-6,
            "{unit:?} → {action:?} → {back:?}"
        );
    }
    assert_eq!(Action::from_unit([-1.0, 0.0]).accel, -BRAKE_RANGE);
    assert_eq!(Action::from_unit([1.0, 0.0]).accel, ACCEL_RANGE);
    // beyond the ranges: clamped; not finite: nothing
    assert_eq!(Action { accel: -20.0, steer: 2.0 }.to_unit(), [-1.0, 1.0]);
    assert_eq!(Action { accel: f64::NAN, steer: f64::INFINITY }.to_unit(), [0.0, 0.0]);
}

#[test]
fn the_kinematics_observation_is_the_state_then_each_near_actor() {
    let mut v = view(8.0, 10.0);
    v.around[0] = Some(Near { position: [12.0, -3.5], velocity: [-8.0, 0.5], yaw: 0.5, size: [4.6, 1.8] });
    v.around[1] = Some(Near { position: [80.0, 0.0], velocity: [0.0; 2], yaw: 0.0, size: [0.5, 0.5] });
    let k = v.kinematics();
    assert_eq!(k.len(), KINEMATICS_DIM);
    assert_eq!(k[..STATE_DIM], v.state());
    let first = &k[STATE_DIM..STATE_DIM + NEAR_FEATURES];
    let expected = [1.0, 0.24, -0.07, -0.8, 0.05, 0.5f64.cos(), 0.5f64.sin(), 0.46, 0.18];
    for (a, b) in first.iter().zip(expected) {
        assert!((a - b).abs() < 1e-12, "{first:?}");
    }
    // beyond the unit the position is clamped; empty places are zeros
    assert_eq!(k[STATE_DIM + NEAR_FEATURES + 1], 1.0);
    assert!(k[STATE_DIM + 2 * NEAR_FEATURES..].iter().all(|&x| x == 0.0));
    assert_eq!(Observation::Kinematics.of(&v), k.to_vec());
}

#[test]
fn observations_by_name_and_width() {
    for (name, observation) in Observation::ALL {
        assert_eq!(Observation::parse(name), Some(observation));
        assert_eq!(observation.name(), name);
        assert_eq!(Observation::of_inputs(observation.width()), Some(observation));
        assert_eq!(observation.of(&view(4.0, 8.0)).len(), observation.width());
    }
    assert_eq!(Observation::parse("pixels"), None);
    // the state is scaled to about 1: nothing beyond the caps, "none" at the cap
    let state = view(4.0, 8.0).state();
    assert_eq!((state[7], state[8], state[10], state[11]), (0.0, 1.0, 0.0, 1.0));
    assert!(state.iter().all(|v| v.is_finite() && v.abs() <= 10.0), "{state:?}");
}

#[test]
fn the_shipped_models_load_by_name() {
    for model in pretrained::ALL {
        let actor = model.load().unwrap();
        assert_eq!(actor.name(), model.name);
        assert_eq!(actor.inputs(), KINEMATICS_DIM, "{} reads the kinematics", model.name);
        // its critics are a safetensors file beside it, with the first critic's layers
        let critics = candle_core::safetensors::load_buffer(model.critics, &Device::Cpu).unwrap();
        let first = if model.name == "ppo" { "v.fc1.weight" } else { "q1.fc1.weight" };
        assert!(critics.contains_key(first), "{}: {:?}", model.name, critics.keys().collect::<Vec<_>>());
    }
    assert!(pretrained::find("ddpg").is_none());
}
