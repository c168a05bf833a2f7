//! The embedding models against figures sentence-transformers publishes, and the batching
//! contract (padding never changes a text's vector). The models must be installed
//! (`tadslc model fetch minilm`, `tadslc model fetch mpnet`); without them these tests skip
//! with a message, unless `TAD_REQUIRE_MODEL=1` (CI sets it), which fetches them first.

use std::sync::OnceLock;

use tad_embed::{Embedder, cosine};

/// The loaded model, fetched first when `TAD_REQUIRE_MODEL` is set; `None` (with a note)
/// when it is not installed.
fn embedder(name: &str) -> Option<&'static Embedder> {
    static MINILM: OnceLock<Option<Embedder>> = OnceLock::new();
    static MPNET: OnceLock<Option<Embedder>> = OnceLock::new();
    let model = tad_models::model(name).unwrap();
    let cell = if model.name == "all-minilm-l6-v2" { &MINILM } else { &MPNET };
    cell.get_or_init(|| {
        tad_models::for_tests(name)?;
        Some(Embedder::load(model).unwrap_or_else(|e| panic!("{e}")))
    })
    .as_ref()
}

/// The pairwise similarities of three texts: (0–1, 0–2, 1–2).
fn similarities(e: &Embedder, texts: [&str; 3]) -> [f32; 3] {
    let v = e.embed(&texts).unwrap();
    assert_eq!(v.len(), 3);
    for x in &v {
        assert_eq!(x.len(), e.dim());
        assert!((cosine(x, x) - 1.0).abs() < 1e-4, "not unit length");
    }
    [cosine(&v[0], &v[1]), cosine(&v[0], &v[2]), cosine(&v[1], &v[2])]
}

fn assert_close(got: [f32; 3], want: [f32; 3], tolerance: f32) {
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() <= tolerance, "similarities {got:?}, published {want:?}");
    }
}

const QUICKSTART: [&str; 3] = ["The weather is lovely today.", "It's so sunny outside!", "He drove to the stadium."];

/// sentence-transformers' quickstart (sbert.net, "Computing Embeddings"): `tensor([[1.0000,
/// 0.6660, 0.1046], [0.6660, 1.0000, 0.1411], ...])` with all-MiniLM-L6-v2.
#[test]
fn minilm_reproduces_the_quickstart_similarities() {
    let Some(e) = embedder("minilm") else { return };
    assert_eq!((e.name(), e.dim()), ("all-minilm-l6-v2", 384));
    assert_close(similarities(e, QUICKSTART), [0.6660, 0.1046, 0.1411], 0.002);
}

/// A text's vector is the same alone and beside a longer one (padding is masked out of
/// attention and pooling), and the output keeps the input's order.
fn padding_invariance(e: &Embedder) {
    let short = "A car brakes.";
    let long = "A pedestrian crosses the road at the junction while a truck turns left and a cyclist waits behind the stop line.";
    let alone = e.embed(&[short]).unwrap();
    let batch = e.embed(&[long, short, long]).unwrap();
    let diff = alone[0].iter().zip(&batch[1]).map(|(a, b)| (a - b).abs()).fold(0f32, f32::max);
    assert!(diff < 1e-4, "{}: the short text moved by {diff} when padded", e.name());
    assert!(cosine(&batch[0], &batch[2]) > 0.9999);
    assert!(cosine(&batch[0], &batch[1]) < 0.99);
}

#[test]
fn minilm_vectors_do_not_depend_on_the_batch() {
    let Some(e) = embedder("minilm") else { return };
    padding_invariance(e);
}

#[test]
fn no_texts_give_no_vectors_and_a_long_text_is_truncated() {
    let Some(e) = embedder("minilm") else { return };
    assert!(e.embed(&[]).unwrap().is_empty());
    // far beyond 256 tokens: truncated, so the tail does not matter
    let long = "the ego vehicle keeps its lane ".repeat(400);
    let longer = format!("{long} and then a deer jumps out");
    let v = e.embed(&[&long, &longer, ""]).unwrap();
    assert_eq!(v.len(), 3);
    assert!(cosine(&v[0], &v[1]) > 0.9999, "text past the limit changed the vector");
    assert!((cosine(&v[2], &v[2]) - 1.0).abs() < 1e-4, "the empty text has a unit vector too");
}

#[test]
fn a_language_model_is_not_an_embedder() {
    let err = Embedder::load(tad_models::model(tad_models::DEFAULT).unwrap()).err().unwrap();
    assert!(err.contains("not a sentence-embedding model"), "{err}");
}

/// The same sentences in the `SentenceTransformer` class's documented example (sbert.net,
/// package reference), which loads all-mpnet-base-v2: `tensor([[1.0000, 0.6817, 0.0492],
/// [0.6817, 1.0000, 0.0421], ...])`.
#[test]
fn mpnet_reproduces_the_documented_similarities() {
    let Some(e) = embedder("mpnet") else { return };
    assert_eq!((e.name(), e.dim()), ("all-mpnet-base-v2", 768));
    assert_close(similarities(e, QUICKSTART), [0.6817, 0.0492, 0.0421], 0.002);
}

#[test]
fn mpnet_vectors_do_not_depend_on_the_batch_and_long_texts_are_truncated() {
    let Some(e) = embedder("mpnet") else { return };
    padding_invariance(e);
    let long = "a bus stops at the kerb ".repeat(200);
    let longer = format!("{long} while it snows");
    let v = e.embed(&[&long, &longer]).unwrap();
    assert!(cosine(&v[0], &v[1]) > 0.9999, "text past 384 tokens changed the vector");
}

/// Milliseconds per sentence for a batch of 32 short sentences (printed; run with
/// `--nocapture`); asserts only that it finishes and gives 32 vectors.
#[test]
fn speed_of_a_batch_of_short_sentences() {
    let sentences: Vec<String> = (0..32)
        .map(|i| format!("Vehicle {i} changes lanes in front of the ego car at {} km/h on a wet road.", 30 + i))
        .collect();
    let texts: Vec<&str> = sentences.iter().map(String::as_str).collect();
    for name in ["minilm", "mpnet"] {
        let Some(e) = embedder(name) else { continue };
        e.embed(&texts[..2]).unwrap();
        let start = std::time::Instant::now();
        let v = e.embed(&texts).unwrap();
        let ms = start.elapsed().as_secs_f64() * 1000.0 / texts.len() as f64;
        assert_eq!(v.len(), 32);
        eprintln!("{}: {ms:.1} ms per sentence (batch of 32)", e.name());
    }
}
