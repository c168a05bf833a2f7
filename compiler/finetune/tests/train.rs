//! LoRA training: on tiny random llama and qwen2 models built in memory (the loss falls,
//! the adapter round-trips, B = 0 is the base model, gradients match finite differences,
//! malformed adapters are errors), and on the real local models when they are installed
//! (or `TAD_REQUIRE_MODEL=1`: SmolLM2-135M, a llama, and Qwen2.5-Coder-0.5B, a qwen2): the
//! f32 training forward pass against tad-local's quantized decoder, with and without an
//! adapter, and a few steps of training.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use tad_finetune::{
    Adapter, Config, Example, FinetuneError, LoraSet, Message, Progress, Rng, Sample, Target, Weights, uniform,
};
use tad_local::{Arch, Lora, Shape};

fn tiny_shape() -> Shape {
    tiny(Arch::Llama)
}

fn tiny(arch: Arch) -> Shape {
    Shape {
        arch,
        layers: 2,
        dim: 32,
        hidden: 64,
        heads: 4,
        kv_heads: 2,
        head_dim: 8,
        context: 256,
        eps: 1e-5,
        rope_base: 10_000.0,
    }
}

/// A fresh directory under the build's scratch space, not the system's `/tmp`.
fn scratch(name: &str) -> PathBuf {
    tad_test_support::scratch(Path::new(env!("CARGO_TARGET_TMPDIR")), &format!("tad-finetune-{name}"))
}

fn cosine(a: &[f32], b: &[f32]) -> f32 {
    let dot: f32 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let norm = |v: &[f32]| v.iter().map(|x| x * x).sum::<f32>().sqrt();
    dot / (norm(a) * norm(b))
}

fn argmax(v: &[f32]) -> usize {
    v.iter().enumerate().fold((0, f32::NEG_INFINITY), |(bi, bv), (i, &x)| if x > bv { (i, x) } else { (bi, bv) }).0
}

/// An adapter with random A and B (so it changes the model), in PEFT's layout.
fn random_adapter(shape: &Shape, rank: usize, targets: &[Target], seed: u64, bound: f32) -> Adapter {
    let mut rng = Rng(seed);
    let mut layers = BTreeMap::new();
    for layer in 0..shape.layers {
        for &t in targets {
            let (inputs, outputs) = t.dims(shape);
            let a = (0..rank * inputs).map(|_| uniform(&mut rng, 1.0 / (inputs as f32).sqrt())).collect();
            let b = (0..outputs * rank).map(|_| uniform(&mut rng, bound)).collect();
            layers.insert((layer, t), Lora { a, b, inputs, outputs });
        }
    }
    Adapter {
        rank,
        alpha: 2.0 * rank as f32,
        rslora: false,
        targets: targets.to_vec(),
        base_model: Config::default().base_model,
        layers,
        base_prefix: Vec::new(),
    }
}

#[test]
fn the_loss_falls_on_a_repeated_example_and_the_adapter_reloads() {
    for arch in [Arch::Llama, Arch::Qwen2] {
        the_loss_falls_and_the_adapter_reloads(tiny(arch));
    }
}

fn the_loss_falls_and_the_adapter_reloads(shape: Shape) {
    let weights = Weights::random(shape, 40, 7).unwrap();
    let sample = Sample { tokens: vec![1, 5, 9, 3, 12, 30, 2, 8, 17, 25, 4, 33, 6, 21, 11, 39], answer: 6 };
    let samples = vec![sample.clone(); 4];
    let config =
        Config { rank: 4, alpha: 8.0, learning_rate: 1e-2, epochs: 6, max_len: 64, seed: 3, ..Config::default() };
    let out = scratch(&format!("tiny-{:?}", shape.arch));
    let mut seen = Vec::new();
    let report =
        tad_finetune::train_samples(&weights, &samples, &config, &out, &mut |p: &Progress| seen.push(p.clone()))
            .unwrap();
    assert_eq!(report.steps, 24);
    assert_eq!(seen.len(), 24);
    assert_eq!(seen.last().unwrap().epoch, 5);
    let (first, last) = (report.losses[0], *report.losses.last().unwrap());
    assert!(last < 0.5 * first, "{:?}: the loss went from {first} to {last}: {:?}", shape.arch, report.losses);

    // the files hold what was trained: reloaded, the loss is the trained one
    let adapter = Adapter::load(&out).unwrap();
    assert_eq!(adapter.rank, 4);
    assert_eq!(adapter.targets, Target::ALL.to_vec());
    let lora = LoraSet::from_adapter(&adapter, &shape).unwrap();
    let rope = tad_finetune::Rope::new(&shape, 64).unwrap();
    let reloaded =
        weights.loss(&sample.tokens, sample.answer, Some(&lora), &rope, None).unwrap().to_scalar::<f32>().unwrap();
    let base = weights.loss(&sample.tokens, sample.answer, None, &rope, None).unwrap().to_scalar::<f32>().unwrap();
    assert!((base - first).abs() < 1e-4, "step 1's loss {first} is the base model's {base}");
    assert!(reloaded < last * 1.01 + 1e-3, "reloaded {reloaded}, trained {last}");
    // and written again, the same tensors
    let again = scratch(&format!("tiny-again-{:?}", shape.arch));
    lora.to_adapter(&shape, &config.base_model).unwrap().save(&again).unwrap();
    assert_eq!(Adapter::load(&again).unwrap(), adapter);
    let raw = candle_core::safetensors::load(out.join("adapter_model.safetensors"), &candle_core::Device::Cpu).unwrap();
    assert_eq!(raw.len(), 2 * 7 * shape.layers);
    let q_b = &raw["base_model.model.model.layers.1.self_attn.q_proj.lora_B.weight"];
    assert_eq!(q_b.dims(), &[32, 4]);
    let values: Vec<f32> = q_b.flatten_all().unwrap().to_vec1().unwrap();
    assert_eq!(values, adapter.layers[&(1, Target::Q)].b);
    let config: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("adapter_config.json")).unwrap()).unwrap();
    assert_eq!(config["peft_type"], "LORA");
    assert_eq!(config["task_type"], "CAUSAL_LM");
    assert_eq!(config["r"], 4);
    assert_eq!(config["base_model_name_or_path"], tad_local::model(tad_local::ALIGN_DEFAULT).unwrap().upstream);
    // and beside them llama.cpp's GGUF of the same adapter, its q rows in the model's order
    let mut file = std::fs::File::open(out.join(tad_local::GGUF_FILE)).unwrap();
    let gguf = candle_core::quantized::gguf_file::Content::read(&mut file).unwrap();
    assert_eq!(gguf.metadata["general.type"].to_string().unwrap(), "adapter");
    assert_eq!(gguf.tensor_infos.len(), 2 * 7 * shape.layers);
    let q_b = gguf.tensor(&mut file, "blk.1.attn_q.weight.lora_b", &candle_core::Device::Cpu).unwrap();
    let values: Vec<f32> = q_b.dequantize(&candle_core::Device::Cpu).unwrap().flatten_all().unwrap().to_vec1().unwrap();
    let expected = tad_local::hf_to_gguf_rows(&adapter.layers[&(1, Target::Q)].b, 4, Target::Q, &shape);
    assert_eq!(values, expected.iter().map(|v| v * adapter.scale()).collect::<Vec<_>>());
}

#[test]
fn a_resumed_run_ends_where_an_uninterrupted_one_does() {
    let shape = tiny_shape();
    let weights = Weights::random(shape, 40, 11).unwrap();
    let samples: Vec<Sample> = (0..5u32)
        .map(|i| Sample { tokens: (0..12).map(|j| (i * 7 + j * 3) % 40).collect(), answer: 4 + i as usize % 3 })
        .collect();
    let config = Config {
        rank: 2,
        alpha: 4.0,
        targets: vec![Target::Q, Target::V, Target::Down],
        learning_rate: 5e-3,
        epochs: 2,
        accumulate: 2,
        max_len: 64,
        seed: 9,
        checkpoint_every: 2,
        ..Config::default()
    };
    let whole = scratch("whole");
    let full = tad_finetune::train_samples(&weights, &samples, &config, &whole, &mut |_| {}).unwrap();
    assert_eq!(full.steps, 6); // 3 steps an epoch (2 + 2 + 1 examples)

    // stop after the checkpoint at step 4, then resume
    let part = scratch("part");
    let stopped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tad_finetune::train_samples(&weights, &samples, &config, &part, &mut |p| {
            if p.step == 4 {
                assert!(p.checkpoint.is_some());
                panic!("interrupted after step 4");
            }
        })
    }));
    assert!(stopped.is_err());
    assert!(!part.join("adapter_model.safetensors").exists());
    let resume = Config { resume: true, ..config.clone() };
    let rest = tad_finetune::train_samples(&weights, &samples, &resume, &part, &mut |_| {}).unwrap();
    assert_eq!(rest.resumed_at, Some(4));
    assert_eq!(rest.steps_run, 2);
    assert_eq!(rest.losses.len(), 6);
    for (a, b) in rest.losses.iter().zip(&full.losses) {
        assert!((a - b).abs() < 1e-5, "{:?} vs {:?}", rest.losses, full.losses);
    }
    let (a, b) = (Adapter::load(&whole).unwrap(), Adapter::load(&part).unwrap());
    for (key, lora) in &a.layers {
        let other = &b.layers[key];
        let diff = lora.b.iter().zip(&other.b).map(|(x, y)| (x - y).abs()).fold(0f32, f32::max);
        assert!(diff < 1e-5, "{key:?} differs by {diff}");
    }
    // a checkpoint of another run is refused, as the caller's to fix
    let other = Config { seed: 10, ..resume };
    let refused = tad_finetune::train_samples(&weights, &samples, &other, &part, &mut |_| {}).unwrap_err();
    assert!(matches!(&refused, FinetuneError::Setup(m) if m.contains("another run")), "{refused:?}");
}

#[test]
fn with_b_zero_the_adapter_is_the_base_model_and_gradients_match_finite_differences() {
    for arch in [Arch::Llama, Arch::Qwen2] {
        b_zero_is_the_base_model_and_gradients_match(tiny(arch));
    }
}

fn b_zero_is_the_base_model_and_gradients_match(shape: Shape) {
    let weights = Weights::random(shape, 40, 5).unwrap();
    let tokens = [3u32, 14, 15, 9, 26, 5, 35, 8, 9, 7];
    let zero = LoraSet::new(&shape, 4, 8.0, &Target::ALL, 1).unwrap();
    assert_eq!(weights.logits(&tokens, Some(&zero)).unwrap(), weights.logits(&tokens, None).unwrap());

    // the loss's gradient in one element of B and of A against central differences
    let adapter = random_adapter(&shape, 4, &Target::ALL, 2, 0.2);
    let lora = LoraSet::from_adapter(&adapter, &shape).unwrap();
    let rope = tad_finetune::Rope::new(&shape, tokens.len()).unwrap();
    let loss = weights.loss(&tokens, 4, Some(&lora), &rope, None).unwrap();
    let grads = loss.backward().unwrap();
    for (name, index) in [
        ("base_model.model.model.layers.0.self_attn.q_proj.lora_B.weight", 5),
        ("base_model.model.model.layers.1.self_attn.k_proj.lora_A.weight", 17),
        ("base_model.model.model.layers.1.mlp.down_proj.lora_B.weight", 3),
    ] {
        let var = lora.named().into_iter().find(|(n, _)| n == name).unwrap().1;
        let analytic: Vec<f32> = grads.get(var.as_tensor()).unwrap().flatten_all().unwrap().to_vec1().unwrap();
        let original: Vec<f32> = var.as_tensor().flatten_all().unwrap().to_vec1().unwrap();
        let at = |delta: f32| {
            let mut v = original.clone();
            v[index] += delta;
            var.set(&candle_core::Tensor::from_vec(v, var.shape(), &candle_core::Device::Cpu).unwrap()).unwrap();
            weights.loss(&tokens, 4, Some(&lora), &rope, None).unwrap().to_scalar::<f32>().unwrap() as f64
        };
        let h = 1e-2;
        let numeric = (at(h) - at(-h)) / (2.0 * h as f64);
        at(0.0);
        let a = analytic[index] as f64;
        let arch = shape.arch;
        assert!(
            (a - numeric).abs() < 0.02 * a.abs().max(numeric.abs()) + 1e-4,
            "{arch:?} {name}[{index}]: {a} vs {numeric}"
        );
        assert!(a.abs() > 1e-5, "{name}[{index}]: a zero gradient proves nothing");
    }
}

#[test]
fn recomputing_each_layer_gives_the_whole_graphs_loss_and_gradients() {
    for arch in [Arch::Llama, Arch::Qwen2] {
        recomputed_gradients_match(Shape { layers: 3, ..tiny(arch) });
    }
}

fn recomputed_gradients_match(shape: Shape) {
    let weights = Weights::random(shape, 40, 11).unwrap();
    // 295 answer rows: the head takes them in three slices
    let tokens: Vec<u32> = (0..300u32).map(|i| (i * 7 + i / 3) % 40).collect();
    let lora = LoraSet::from_adapter(&random_adapter(&shape, 4, &Target::ALL, 3, 0.2), &shape).unwrap();
    let rope = tad_finetune::Rope::new(&shape, tokens.len()).unwrap();
    let loss = weights.loss(&tokens, 5, Some(&lora), &rope, None).unwrap();
    let whole = loss.backward().unwrap();
    let (value, recomputed) = weights.loss_recomputed(&tokens, 5, &lora, &rope, None).unwrap();
    let expected = loss.to_scalar::<f32>().unwrap();
    assert!((value - expected).abs() <= 1e-6 * expected, "{value} against {expected}");
    for (name, var) in lora.named() {
        let grad = |store: &candle_core::backprop::GradStore| -> Vec<f32> {
            let g = store.get(var.as_tensor()).unwrap_or_else(|| panic!("{name}: no gradient"));
            g.flatten_all().unwrap().to_vec1().unwrap()
        };
        let (a, b) = (grad(&whole), grad(&recomputed));
        let scale = a.iter().fold(0f32, |m, x| m.max(x.abs()));
        assert!(scale > 0.0 || name.contains("lora_A"), "{name}: a zero gradient proves nothing");
        let worst = a.iter().zip(&b).fold(0f32, |m, (x, y)| m.max((x - y).abs()));
        assert!(worst <= 1e-5 * scale.max(1e-3), "{:?} {name}: differs by {worst} (largest {scale})", shape.arch);
    }
}

#[test]
fn a_frozen_prefix_gives_the_loss_of_the_whole_sequence() {
    for arch in [Arch::Llama, Arch::Qwen2] {
        frozen_prefix_matches(Shape { layers: 3, ..tiny(arch) });
    }
}

fn frozen_prefix_matches(shape: Shape) {
    let weights = Weights::random(shape, 40, 13).unwrap();
    let tokens: Vec<u32> = (0..60u32).map(|i| (i * 11 + i / 5) % 40).collect();
    let lora = LoraSet::from_adapter(&random_adapter(&shape, 4, &Target::ALL, 4, 0.2), &shape).unwrap();
    let rope = tad_finetune::Rope::new(&shape, tokens.len()).unwrap();
    let whole = weights.loss(&tokens, 30, Some(&lora), &rope, None).unwrap().to_scalar::<f32>().unwrap();
    // the prefix read with the same adapter: the suffix's loss is the whole sequence's
    let prefix = weights.prefix(&tokens[..20], Some(&lora), &rope).unwrap();
    let kept = weights.loss(&tokens[20..], 10, Some(&lora), &rope, Some(&prefix)).unwrap();
    let (recomputed, grads) = weights.loss_recomputed(&tokens[20..], 10, &lora, &rope, Some(&prefix)).unwrap();
    let kept = kept.to_scalar::<f32>().unwrap();
    assert!((kept - whole).abs() <= 1e-5 * whole, "{:?}: {kept} against {whole}", shape.arch);
    assert!((recomputed - whole).abs() <= 1e-5 * whole, "{:?}: {recomputed} against {whole}", shape.arch);
    assert!(lora.named().iter().all(|(_, v)| grads.get(v.as_tensor()).is_some()));
    // read by the base model, the prefix differs: the answer's loss does too
    let base = weights.prefix(&tokens[..20], None, &rope).unwrap();
    let other = weights.loss(&tokens[20..], 10, Some(&lora), &rope, Some(&base)).unwrap().to_scalar::<f32>().unwrap();
    assert!((other - whole).abs() > 1e-4, "{:?}: the prefix's keys and values were not read", shape.arch);
}

#[test]
fn training_with_a_frozen_prefix_reads_it_once_and_learns() {
    let shape = tiny_shape();
    let weights = Weights::random(shape, 40, 17).unwrap();
    let system: Vec<u32> = (0..24u32).map(|i| (i * 5 + 1) % 40).collect();
    let samples: Vec<Sample> = (0..3u32)
        .map(|k| {
            let mut tokens = system.clone();
            tokens.extend([30 + k, 31, 2, 3 + k, 4, 5 + k, 6]);
            Sample { answer: system.len() + 2, tokens }
        })
        .collect();
    let config = Config {
        rank: 4,
        alpha: 8.0,
        epochs: 6,
        learning_rate: 1e-2,
        seed: 3,
        frozen_prefix: true,
        ..Config::default()
    };
    let out = scratch("frozen-prefix");
    let report = tad_finetune::train_samples(&weights, &samples, &config, &out, &mut |_| {}).unwrap();
    // the samples share the system tokens and nothing after them
    assert_eq!(report.prefix, system.len());
    assert_eq!(report.tokens, 6 * 3 * 7);
    let (first, last) = (report.losses[0], *report.losses.last().unwrap());
    assert!(last < 0.5 * first, "the loss fell only from {first} to {last}");
    // the adapter keeps the prefix it learnt to follow
    assert_eq!(Adapter::load(&out).unwrap().base_prefix, system);
    // trained further from there, it starts where it ended, not from the base model
    let further = Config { epochs: 1, from: Some(Adapter::load(&out).unwrap()), ..config.clone() };
    let again = tad_finetune::train_samples(&weights, &samples, &further, &scratch("further"), &mut |_| {}).unwrap();
    assert!(again.losses[0] < 0.5 * first, "from the adapter: {} against {first}", again.losses[0]);
    // of another rank it is refused, before anything is read
    let other = Config { rank: 2, ..further };
    let e = tad_finetune::train_samples(&weights, &samples, &other, &scratch("other"), &mut |_| {}).unwrap_err();
    assert!(matches!(&e, tad_finetune::FinetuneError::Setup(m) if m.contains("rank 4")), "{e}");
}

fn edit_tensors(d: &Path, edit: &dyn Fn(&mut std::collections::HashMap<String, candle_core::Tensor>)) {
    let path = d.join("adapter_model.safetensors");
    let mut t = candle_core::safetensors::load(&path, &candle_core::Device::Cpu).unwrap();
    edit(&mut t);
    candle_core::safetensors::save(&t, &path).unwrap();
}

fn write_adapter(dir: &Path, adapter: &Adapter) {
    adapter.save(dir).unwrap();
}

#[test]
fn a_malformed_adapter_is_an_error() {
    let shape = tiny_shape();
    let good = random_adapter(&shape, 4, &[Target::Q, Target::Up], 1, 0.1);
    let dir = scratch("malformed");
    write_adapter(&dir, &good);
    let loaded = Adapter::load(&dir).unwrap();
    loaded.check(&shape).unwrap();
    assert_eq!(loaded, good);

    // another model's shape
    let wider = Shape { dim: 64, ..shape };
    assert!(loaded.check(&wider).unwrap_err().contains("features"));
    let deeper = Shape { layers: 3, ..shape };
    assert!(loaded.check(&deeper).unwrap_err().contains("layers"));
    assert!(LoraSet::from_adapter(&loaded, &wider).is_err());

    // a missing config, a garbage config, a config of another kind
    let case = |name: &str, edit: &dyn Fn(&Path)| -> String {
        let d = scratch(name);
        write_adapter(&d, &good);
        edit(&d);
        Adapter::load(&d).expect_err(name)
    };
    case("no-config", &|d| std::fs::remove_file(d.join("adapter_config.json")).unwrap());
    // a frozen prefix round-trips; one that is not token ids is refused
    let d = scratch("base-prefix");
    let with_prefix = Adapter { base_prefix: vec![3, 0, 4_000_000_000], ..good.clone() };
    write_adapter(&d, &with_prefix);
    assert_eq!(Adapter::load(&d).unwrap(), with_prefix);
    write_adapter(&d, &good);
    assert_eq!(Adapter::load(&d).unwrap().base_prefix, Vec::<u32>::new());
    for (name, text) in [("prefix-negative", r#"{"tokens":[1,-2]}"#), ("prefix-wide", r#"{"tokens":[4294967296]}"#)] {
        let e = case(name, &|d| std::fs::write(d.join(tad_local::BASE_PREFIX_FILE), text).unwrap());
        assert!(e.contains("token ids"), "{e}");
    }
    case("prefix-garbage", &|d| std::fs::write(d.join(tad_local::BASE_PREFIX_FILE), "[1, 2").unwrap());
    case("bad-config", &|d| std::fs::write(d.join("adapter_config.json"), "{not json").unwrap());
    case("not-lora", &|d| {
        std::fs::write(
            d.join("adapter_config.json"),
            r#"{"peft_type":"IA3","r":4,"lora_alpha":8,"target_modules":["q_proj"]}"#,
        )
        .unwrap()
    });
    let text = |r: u64, targets: &str| {
        format!(r#"{{"peft_type":"LORA","r":{r},"lora_alpha":8,"target_modules":{targets},"bias":"none"}}"#)
    };
    // a rank the tensors do not have
    let e =
        case("rank", &|d| std::fs::write(d.join("adapter_config.json"), text(8, r#"["q_proj","up_proj"]"#)).unwrap());
    assert!(e.contains("rank 8"), "{e}");
    // tensors for a module the config does not name
    case("targets", &|d| std::fs::write(d.join("adapter_config.json"), text(4, r#"["q_proj"]"#)).unwrap());
    case("unknown-target", &|d| std::fs::write(d.join("adapter_config.json"), text(4, r#"["lm_head"]"#)).unwrap());
    // garbage, truncated or missing weights
    case("garbage", &|d| std::fs::write(d.join("adapter_model.safetensors"), b"\x10\0\0\0\0\0\0\0garbage").unwrap());
    case("empty", &|d| std::fs::write(d.join("adapter_model.safetensors"), b"").unwrap());
    case("huge-header", &|d| std::fs::write(d.join("adapter_model.safetensors"), u64::MAX.to_le_bytes()).unwrap());
    case("truncated", &|d| {
        let bytes = std::fs::read(d.join("adapter_model.safetensors")).unwrap();
        std::fs::write(d.join("adapter_model.safetensors"), &bytes[..bytes.len() / 2]).unwrap()
    });
    case("no-weights", &|d| std::fs::remove_file(d.join("adapter_model.safetensors")).unwrap());
    // a layer without one of its pairs, one half of a pair, a wrong shape, a NaN
    let e = case("missing-pair", &|d| {
        edit_tensors(d, &|t| {
            t.retain(|k, _| !k.contains("layers.0.mlp.up_proj"));
        })
    });
    assert!(e.contains("layer 0 has no up_proj"), "{e}");
    case("half", &|d| {
        edit_tensors(d, &|t| {
            t.remove("base_model.model.model.layers.1.self_attn.q_proj.lora_B.weight");
        })
    });
    case("shape", &|d| {
        edit_tensors(d, &|t| {
            let wrong =
                candle_core::Tensor::zeros((4, 4, 2), candle_core::DType::F32, &candle_core::Device::Cpu).unwrap();
            t.insert("base_model.model.model.layers.1.self_attn.q_proj.lora_A.weight".into(), wrong);
        })
    });
    case("nan", &|d| {
        edit_tensors(d, &|t| {
            let nan = candle_core::Tensor::full(f32::NAN, (4, 32), &candle_core::Device::Cpu).unwrap();
            t.insert("base_model.model.model.layers.1.self_attn.q_proj.lora_A.weight".into(), nan);
        })
    });
    case("stray", &|d| {
        edit_tensors(d, &|t| {
            let x = candle_core::Tensor::zeros((4, 32), candle_core::DType::F32, &candle_core::Device::Cpu).unwrap();
            t.insert("base_model.model.lm_head.lora_A.weight".into(), x);
        })
    });
    // a dimension that does not fit the model is caught by check, not by a panic later
    let d = scratch("wide-in");
    let mut wide = good.clone();
    for lora in wide.layers.values_mut() {
        lora.inputs *= 2;
        lora.a = vec![0.0; lora.a.len() * 2];
    }
    write_adapter(&d, &wide);
    assert!(Adapter::load(&d).unwrap().check(&shape).is_err());
}

#[test]
fn examples_are_tokenized_as_the_engine_reads_them() {
    for path in ggufs() {
        examples_are_tokenized_on(&path);
    }
}

fn examples_are_tokenized_on(path: &Path) {
    let mut file = std::fs::File::open(path).unwrap();
    let content = candle_core::quantized::gguf_file::Content::read(&mut file).unwrap();
    let tokenizer = tad_local::tokenizer(&content).unwrap();
    let example = Example {
        prompt: vec![
            Message { role: "system".into(), content: "Write TAD.".into() },
            Message { role: "user".into(), content: "A bus drives ahead of the ego car.".into() },
        ],
        completion: "scenario bus_ahead {}".into(),
    };
    let (sample, warning) = tad_finetune::tokenize(&tokenizer, &example, 1024).unwrap();
    let sample = sample.unwrap();
    assert!(warning.is_none());
    let (prompt, _) =
        tad_local::chatml(&tokenizer, &[("system", "Write TAD."), ("user", "A bus drives ahead of the ego car.")])
            .unwrap();
    assert_eq!(&sample.tokens[..sample.answer], prompt.as_slice());
    assert_eq!(*sample.tokens.last().unwrap(), tokenizer.token_to_id("<|im_end|>").unwrap());
    let text = tokenizer.decode(&sample.tokens[sample.answer..], false).unwrap();
    assert_eq!(text, "scenario bus_ahead {}<|im_end|>");
    let (cut, warning) = tad_finetune::tokenize(&tokenizer, &example, sample.answer + 2).unwrap();
    assert_eq!(cut.unwrap().tokens.len(), sample.answer + 2);
    assert!(warning.unwrap().contains("cut"));
    let (none, warning) = tad_finetune::tokenize(&tokenizer, &example, sample.answer).unwrap();
    assert!(none.is_none() && warning.unwrap().contains("dropped"));
}

/// The real models installed (all of them with `TAD_REQUIRE_MODEL=1`): a llama and a qwen2.
fn ggufs() -> Vec<PathBuf> {
    [tad_local::SMALLEST, "qwen2.5-coder-0.5b"].into_iter().filter_map(tad_local::for_tests).collect()
}

/// The bounds of B's entries for a random adapter that changes a real model without wrecking
/// it, on q and k alone and on every projection: Qwen2.5 takes smaller ones.
fn adapter_bounds(shape: &Shape) -> (f32, f32) {
    if shape.arch.interleaved() { (2.0, 0.5) } else { (0.3, 0.05) }
}

fn prompt_tokens(path: &Path) -> Vec<u32> {
    let mut file = std::fs::File::open(path).unwrap();
    let content = candle_core::quantized::gguf_file::Content::read(&mut file).unwrap();
    let tokenizer = tad_local::tokenizer(&content).unwrap();
    tad_local::chatml(&tokenizer, &[("user", "A bus drives ahead of the ego car.")]).unwrap().0
}

#[test]
fn the_training_forward_pass_agrees_with_the_quantized_decoder() {
    for path in ggufs() {
        the_training_forward_pass_agrees_on(&path);
    }
}

fn the_training_forward_pass_agrees_on(path: &Path) {
    let tokens = prompt_tokens(path);
    let (weights, _) = Weights::load(path).unwrap();
    let ours = weights.logits(&tokens, None).unwrap();
    let mut engine = tad_local::Engine::load(path, 1).unwrap();
    let theirs = engine.logits(&tokens);
    assert_eq!(ours.len(), theirs.len());
    assert_eq!(argmax(&ours), argmax(&theirs), "{}", path.display());
    assert!(cosine(&ours, &theirs) > 0.99, "{}: cosine {}", path.display(), cosine(&ours, &theirs));
}

#[test]
fn an_adapter_in_the_decoder_agrees_with_the_training_forward_pass() {
    for path in ggufs() {
        an_adapter_agrees_on(&path);
    }
}

fn an_adapter_agrees_on(path: &Path) {
    let tokens = prompt_tokens(path);
    let (weights, _) = Weights::load(path).unwrap();
    let shape = weights.shape;
    let base = weights.logits(&tokens, None).unwrap();
    // q and k alone first: a wrong row order between HF's layout and the GGUF's shows here
    let (qk, all) = adapter_bounds(&shape);
    for (targets, bound) in [(vec![Target::Q, Target::K], qk), (Target::ALL.to_vec(), all)] {
        let adapter = random_adapter(&shape, 8, &targets, 4, bound);
        let dir = scratch(&format!("real-{:?}-{}", shape.arch, targets.len()));
        adapter.save(&dir).unwrap();
        let adapter = Adapter::load(&dir).unwrap();
        let lora = LoraSet::from_adapter(&adapter, &shape).unwrap();
        let trained = weights.logits(&tokens, Some(&lora)).unwrap();
        let changed = cosine(&trained, &base);
        let mut engine = tad_local::Engine::load_with(path, 1, Some(&adapter)).unwrap();
        let decoded = engine.logits(&tokens);
        let c = cosine(&trained, &decoded);
        eprintln!("{:?} {targets:?}: cosine with the base {changed}, with the decoder {c}", shape.arch);
        assert!(changed < 0.995, "the adapter barely changes the model: {changed}");
        assert!(c > 0.995, "{targets:?}: cosine {c}");
        // The decoder keeps its KV cache in half precision. The q/k stress adapter makes the
        // attention scores large, so the cache's rounding can swap close tokens: there the
        // decoder's choice must be among the trained pass's five best; with the moderate
        // adapter on every projection, the same token.
        let (best, chosen) = (argmax(&trained), argmax(&decoded));
        if targets.len() == 2 {
            let above = trained.iter().filter(|&&v| v > trained[chosen]).count();
            assert!(above < 5, "{targets:?}: the decoder's token is {}th of the trained pass's", above + 1);
        } else {
            assert_eq!(best, chosen, "{targets:?}");
        }
        if targets.len() == 2 {
            // the control: B's q/k rows interleaved once more than the model's order (llama:
            // twice; qwen2, whose GGUF keeps Hugging Face's order: once) disagree clearly
            let mut wrong = adapter.clone();
            for ((_, t), lora) in wrong.layers.iter_mut() {
                if t.roped() {
                    lora.b = tad_local::interleave_rows(&lora.b, 8, shape.head_dim);
                }
            }
            let mut engine = tad_local::Engine::load_with(path, 1, Some(&wrong)).unwrap();
            let w = cosine(&trained, &engine.logits(&tokens));
            eprintln!("rows in the wrong order: cosine {w}");
            // (the right order's own distance is the half-precision cache's rounding, which
            // this stress adapter amplifies: on SmolLM2 1 − c moved from 0.0015 to 0.0026 with
            // a change of the order of attention's float additions, 1 − w stays 0.0069)
            assert!(1.0 - w > 2.0 * (1.0 - c), "the wrong order agrees as well: {w} vs {c}");
        }
    }
}

#[test]
fn the_decoder_reads_an_adapters_frozen_prefix_as_training_did() {
    for path in ggufs() {
        the_frozen_prefix_is_read_as_trained_on(&path);
    }
}

fn the_frozen_prefix_is_read_as_trained_on(path: &Path) {
    let tokens = prompt_tokens(path);
    let (weights, _) = Weights::load(path).unwrap();
    let shape = weights.shape;
    let split = tokens.len() - 4;
    let throughout = random_adapter(&shape, 8, &Target::ALL, 5, adapter_bounds(&shape).1);
    let dir = scratch(&format!("real-prefix-{:?}", shape.arch));
    Adapter { base_prefix: tokens[..split].to_vec(), ..throughout.clone() }.save(&dir).unwrap();
    let adapter = Adapter::load(&dir).unwrap();
    let lora = LoraSet::from_adapter(&adapter, &shape).unwrap();
    let trained = weights.logits_after(&tokens[..split], &tokens[split..], Some(&lora)).unwrap();
    let whole = weights.logits(&tokens, Some(&lora)).unwrap();
    let mut engine = tad_local::Engine::load_with(path, 1, Some(&adapter)).unwrap();
    let decoded = engine.logits(&tokens);
    let (c, w) = (cosine(&trained, &decoded), cosine(&whole, &decoded));
    eprintln!("{:?}: cosine with the prefix read by the base model {c}, by the adapter {w}", shape.arch);
    assert!(c > 0.995 && 1.0 - w > 2.0 * (1.0 - c), "{:?}: {c} against {w}", shape.arch);
    // a prompt that does not start with the prefix reads all of it with the adapter
    let mut other = tokens.clone();
    other[1] = other[2];
    let mut plain = tad_local::Engine::load_with(path, 1, Some(&throughout)).unwrap();
    assert_eq!(engine.logits(&other), plain.logits(&other));
}

#[test]
fn a_few_steps_on_the_real_model() {
    for path in ggufs() {
        a_few_steps_on(&path);
    }
}

fn a_few_steps_on(path: &Path) {
    let example = |region: &str| Example {
        prompt: vec![
            Message { role: "system".into(), content: "You write TAD scenarios.".into() },
            Message { role: "user".into(), content: format!("Write a TAD scenario for the region {region}.") },
        ],
        completion: format!("scenario {region}_cut_in {{\n  road: straight_road\n}}\n"),
    };
    let examples = vec![example("urban"), example("highway")];
    let config = Config { rank: 4, alpha: 8.0, epochs: 2, max_len: 128, learning_rate: 1e-3, ..Config::default() };
    let out = scratch(&format!("real-train-{}", path.file_name().unwrap().to_string_lossy()));
    let report = tad_finetune::train(path, &examples, &config, &out, &mut |_| {}).unwrap();
    eprintln!("{}: losses {:?}, {:.1} tokens/s", path.display(), report.losses, report.tokens_per_s);
    assert_eq!(report.steps, 4);
    assert!(report.losses.iter().all(|l| l.is_finite()));
    assert!(report.losses[3] < report.losses[0], "{:?}", report.losses);
    // the adapter drives the decoder: the same vocabulary, other logits
    let adapter = Adapter::load(&out).unwrap();
    let tokens = prompt_tokens(path);
    let tuned = tad_local::Engine::load_with(path, 1, Some(&adapter)).unwrap().logits(&tokens);
    let base = tad_local::Engine::load(path, 1).unwrap().logits(&tokens);
    assert_eq!(tuned.len(), base.len());
    assert_ne!(tuned, base, "the adapter changes nothing");
}
