//! The system message's keys and values kept on disk (`Engine::keep_prompts`), on the
//! smallest model: a second process reads them instead of the prefill and answers the same
//! tokens; a damaged file is read as no file, and replaced. Skips when the model is not
//! installed, unless `TAD_REQUIRE_MODEL=1` (CI), which fetches it.

use tad_llm::{Message, Request, Role};
use tad_local::Engine;

fn request(user: &str) -> Request {
    let system = "You write traffic scenarios. ".repeat(40);
    let mut request = Request::new(vec![Message::text(Role::System, system), Message::text(Role::User, user)]);
    request.max_tokens = 24;
    request.temperature = 0.0;
    request
}

fn kv_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "kv")).collect())
        .unwrap_or_default();
    files.sort();
    files
}

#[test]
fn a_kept_system_message_is_read_not_prefilled_and_gives_the_same_answer() {
    let Some(path) = tad_local::for_tests(tad_local::SMALLEST) else { return };
    let dir = tad_test_support::scratch(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")), "prompt-store");
    let run = |user: &str| {
        let mut engine = Engine::load(&path, 1).unwrap();
        engine.keep_prompts(dir.clone());
        let answer = engine.generate(&request(user)).unwrap();
        (answer.text, answer.usage.prompt_tokens, engine.timing.prefill_tokens)
    };

    let (first, prompt, read) = run("A bus ahead.");
    assert_eq!(read, prompt, "the first process reads the whole prompt");
    let files = kv_files(&dir);
    assert_eq!(files.len(), 1, "the system message is kept");

    let (again, _, read_again) = run("A bus ahead.");
    assert_eq!(again, first, "the kept keys and values are the prefill's");
    assert!(read_again < prompt / 4, "only the user's turn is read: {read_again} of {prompt}");

    // another user turn after the same system message reads the same file
    let (_, other_prompt, other_read) = run("Two cyclists on the left.");
    assert!(other_read < other_prompt / 4);
    assert_eq!(kv_files(&dir), files);

    // a damaged file is no file: the prompt is read whole, the answer is the same, and the
    // file is written again
    let mut bytes = std::fs::read(&files[0]).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x40;
    std::fs::write(&files[0], &bytes).unwrap();
    let (repaired, _, read_whole) = run("A bus ahead.");
    assert_eq!((repaired.as_str(), read_whole), (first.as_str(), prompt));
    let (_, _, read_after) = run("A bus ahead.");
    assert!(read_after < prompt / 4, "the damaged file was replaced");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A repair round's prompt is the last prompt and answer and then the repair: only the
/// repair is read, and the answer is the one an engine reading the whole prompt gives.
#[test]
fn a_repair_round_reads_on_after_the_last_answer() {
    let Some(path) = tad_local::for_tests(tad_local::SMALLEST) else { return };
    let first = request("A bus ahead.");
    let mut engine = Engine::load(&path, 1).unwrap();
    let answer = engine.generate(&first).unwrap();
    let mut repair = first.clone();
    repair.messages.push(Message::text(Role::Assistant, answer.text.clone()));
    repair.messages.push(Message::text(Role::User, "E0500 2:5: unknown weather `sunnyish`. Write the program again."));
    let before = engine.timing;
    let again = engine.generate(&repair).unwrap();
    let read = engine.timing.since(&before).prefill_tokens;
    let added = again.usage.prompt_tokens - answer.usage.prompt_tokens;
    assert!(read + answer.usage.completion_tokens / 2 < added, "read {read} of the {added} new tokens");

    let whole = Engine::load(&path, 1).unwrap().generate(&repair).unwrap();
    assert_eq!(again.text, whole.text, "reading on gives the whole prompt's answer");
}
