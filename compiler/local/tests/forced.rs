//! Tokens a grammar forces (llguidance's fast-forward) are read with the sampled token
//! before them, on the smallest model: the answer is the one decided token by token, most
//! of a rigid grammar's tokens are forced, and the answer stays inside the grammar and the
//! token limit. Skips when the model is not installed, unless `TAD_REQUIRE_MODEL=1` (CI),
//! which fetches it.

use tad_llm::{Constraint, Finish, Message, Request, Role};
use tad_local::Engine;

/// A TAD-shaped grammar: the layout forced, two names and one number chosen.
const GRAMMAR: &str = r#"
start: "```tad\nscenario " NAME " {\n  environment {\n    weather: " WEATHER "\n    time: " TIME "\n  }\n  ego {\n    speed: " SPEED " km/h\n  }\n}\n```"
NAME: /[a-z][a-z_]{0,23}/
WEATHER: "clear" | "rainy" | "cloudy" | "foggy" | "snowy"
TIME: "daytime" | "night" | "dusk" | "dawn"
SPEED: /[1-9][0-9]?/
"#;

fn request(max_tokens: u32) -> Request {
    let system = "You write traffic scenarios in TAD.";
    let user = "A rainy night; the ego drives at 40 km/h.";
    let mut request = Request::new(vec![Message::text(Role::System, system), Message::text(Role::User, user)]);
    request.max_tokens = max_tokens;
    request.temperature = 0.0;
    request.constraint = Constraint::Lark(GRAMMAR.to_string());
    request
}

#[test]
fn forced_tokens_are_read_at_once_and_the_answer_is_the_same() {
    let Some(path) = tad_local::for_tests(tad_local::SMALLEST) else { return };
    let answer = |fast_forward: bool, max_tokens: u32| {
        let mut engine = Engine::load(&path, 1).unwrap();
        engine.set_fast_forward(fast_forward);
        let answer = engine.generate(&request(max_tokens)).unwrap();
        (answer, engine.timing)
    };

    let (slow, slow_timing) = answer(false, 128);
    let (fast, fast_timing) = answer(true, 128);
    assert_eq!(slow_timing.forced_tokens, 0);
    assert_eq!(fast.text, slow.text, "fast-forward changes no token");
    assert_eq!(fast.finish, Finish::Stop);
    assert!(fast.text.starts_with("```tad\nscenario ") && fast.text.ends_with("}\n}\n```"), "{}", fast.text);
    let tokens = fast.usage.completion_tokens;
    assert_eq!(tokens, slow.usage.completion_tokens);
    assert!(
        2 * fast_timing.forced_tokens > tokens,
        "most of this grammar's tokens are forced: {} of {tokens}",
        fast_timing.forced_tokens
    );

    // a limit inside a forced run cuts the run there
    let limit = (tokens / 2) as u32;
    let (cut, _) = answer(true, limit);
    assert_eq!((cut.finish, cut.usage.completion_tokens), (Finish::Length, limit as u64));
    assert!(fast.text.starts_with(&cut.text), "{:?} is not the start of {:?}", cut.text, fast.text);
}
