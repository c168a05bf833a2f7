//! Times the decoder reading a prompt from position 0, then decoding, for work on its
//! kernels: `cargo run --release -p tad-local --example prefill -- GGUF [TOKENS] [THREADS] [RUNS]`.
//! The prompt is the tokenizer's reading of a fixed text, repeated to `TOKENS`; the best of
//! `RUNS` is printed with the last logits' argmax, so a kernel change that moves the
//! answer shows. Decoding is 32 greedy tokens after the text, unconstrained.

use std::time::Instant;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(gguf) = args.first() else {
        return Err("usage: prefill GGUF [TOKENS] [THREADS] [RUNS]".into());
    };
    let number = |i: usize, default: usize| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(default);
    let (len, threads, runs) = (number(1, 256), number(2, 1), number(3, 3));
    let mut engine = tad_local::Engine::load(std::path::Path::new(gguf), threads).map_err(|e| e.to_string())?;
    let text = "A rainy evening at a four-way junction: the ego waits at the red light while two \
                pedestrians cross from the right and an oncoming truck turns left. ";
    let request = tad_llm::Request::new(vec![tad_llm::Message::text(tad_llm::Role::User, text)]);
    let once = engine.prompt_tokens(&request).map_err(|e| e.to_string())?;
    let tokens: Vec<u32> = once.iter().copied().cycle().take(len).collect();
    let mut best = f64::INFINITY;
    let mut top = 0;
    for _ in 0..runs {
        let start = Instant::now();
        let logits = engine.logits(&tokens);
        best = best.min(start.elapsed().as_secs_f64());
        top = (0..logits.len()).max_by(|&a, &b| logits[a].total_cmp(&logits[b])).unwrap_or(0);
    }
    println!("{len} tokens, {threads} thread(s): best {best:.2} s, {:.1} tokens/s, argmax {top}", len as f64 / best);
    let before = engine.timing;
    let answer = engine.generate(&tad_llm::Request { max_tokens: 32, ..request }).map_err(|e| e.to_string())?;
    let spent = engine.timing.since(&before);
    println!(
        "decode: {} tokens in {:.2} s, {:.2} tokens/s: {:?}",
        spent.decode_tokens,
        spent.decode_s,
        spent.decode_tokens as f64 / spent.decode_s.max(1e-9),
        answer.text.chars().take(40).collect::<String>()
    );
    Ok(())
}
