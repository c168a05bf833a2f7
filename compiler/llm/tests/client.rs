//! The client against a scripted server on 127.0.0.1: answers, streams, retries (429 with
//! Retry-After, 5xx, dropped connections), timeouts, errors in words, the concurrency limit
//! and token accounting.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use tad_llm::{Client, Config, Constraint, Dialect, ErrorKind, Finish, Message, Request, Role};
use tad_test_support::fake_llm::{FakeLlm, Reply};

fn config(server: &FakeLlm) -> Config {
    let mut c = Config::new(server.base_url.clone(), "fake");
    c.backoff = Duration::from_millis(10);
    c.api_key = Some("sk-test-secret-key".into());
    c
}

fn request() -> Request {
    Request::new(vec![Message::text(Role::System, "You write TAD."), Message::text(Role::User, "A bus ahead.")])
}

fn run<T>(f: impl std::future::Future<Output = T>) -> T {
    tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap().block_on(f)
}

#[test]
fn an_answer_is_read_and_its_tokens_counted() {
    let server = FakeLlm::script(vec![Reply::chat("scenario a {\n}")]);
    let client = Client::new(config(&server)).unwrap();
    let answer = run(client.chat(&request(), None)).unwrap();
    assert_eq!((answer.text.as_str(), answer.finish, answer.attempts), ("scenario a {\n}", Finish::Stop, 1));
    assert_eq!(client.usage().prompt_tokens, 100);
    let body = &server.requests()[0];
    assert_eq!((body["model"].as_str(), body["messages"][1]["content"].as_str()), (Some("fake"), Some("A bus ahead.")));
}

#[test]
fn a_429_waits_as_long_as_retry_after_says_then_succeeds() {
    let server = FakeLlm::script(vec![
        Reply::status(429, r#"{"error":{"message":"slow down","type":"rate_limit"}}"#).with_header("retry-after", "1"),
        Reply::chat("ok"),
    ]);
    let client = Client::new(config(&server)).unwrap();
    let start = Instant::now();
    let answer = run(client.chat(&request(), None)).unwrap();
    assert!(start.elapsed() >= Duration::from_millis(950), "waited only {:?}", start.elapsed());
    assert_eq!((answer.text.as_str(), answer.attempts), ("ok", 2));
}

#[test]
fn a_retry_after_longer_than_allowed_fails_at_once_in_words() {
    let server = FakeLlm::script(vec![Reply::status(429, "{}").with_header("retry-after", "3600")]);
    let client = Client::new(config(&server)).unwrap();
    let error = run(client.chat(&request(), None)).unwrap_err();
    assert_eq!(error.kind, ErrorKind::RateLimit);
    assert!(error.to_string().contains("asks to wait 3600 s"), "{error}");
    assert_eq!(server.requests().len(), 1);
}

#[test]
fn server_errors_and_dropped_connections_are_retried_up_to_the_limit() {
    let server = FakeLlm::script(vec![Reply::status(503, "overloaded"), Reply::Drop, Reply::chat("fine")]);
    let client = Client::new(config(&server)).unwrap();
    assert_eq!(run(client.chat(&request(), None)).unwrap().attempts, 3);

    let failing = FakeLlm::script(vec![Reply::status(500, r#"{"error":{"message":"boom"}}"#)]);
    let error = run(Client::new(config(&failing)).unwrap().chat(&request(), None)).unwrap_err();
    assert_eq!((error.kind, error.attempts), (ErrorKind::Server, 3));
    assert!(error.to_string().contains("boom") && error.to_string().contains("after 3 attempts"), "{error}");
}

#[test]
fn request_errors_are_not_retried_and_the_key_is_never_shown() {
    let server = FakeLlm::script(vec![Reply::status(
        401,
        r#"{"error":{"message":"Incorrect API key provided: sk-test-secret-key","code":"invalid_api_key"}}"#,
    )]);
    let error = run(Client::new(config(&server)).unwrap().chat(&request(), None)).unwrap_err();
    assert_eq!((error.kind, server.requests().len()), (ErrorKind::Auth, 1));
    assert!(!error.to_string().contains("sk-test-secret-key"), "{error}");
    assert!(error.to_string().contains("TADSL_LLM_API_KEY"));
}

#[test]
fn a_silent_server_times_out() {
    let server = FakeLlm::script(vec![Reply::Delay(Duration::from_secs(5), Box::new(Reply::chat("late")))]);
    let mut c = config(&server);
    c.timeout = Duration::from_millis(300);
    c.max_retries = 1;
    let error = run(Client::new(c).unwrap().chat(&request(), None)).unwrap_err();
    assert_eq!((error.kind, error.attempts), (ErrorKind::Timeout, 2));
}

#[test]
fn nothing_listening_is_a_clear_connect_error() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let url = format!("http://{}/v1", listener.local_addr().unwrap());
    drop(listener);
    let mut c = Config::new(url, "m");
    c.max_retries = 0;
    let error = run(Client::new(c).unwrap().chat(&request(), None)).unwrap_err();
    assert_eq!(error.kind, ErrorKind::Connect);
    assert!(error.to_string().contains("is the server running"), "{error}");
}

#[test]
fn a_streamed_answer_arrives_in_pieces_with_its_usage() {
    let text = "scenario streamed {\n  ego {\n    lane: 1\n  }\n}\n";
    let server = FakeLlm::script(vec![Reply::Stream(text.into())]);
    let client = Client::new(config(&server)).unwrap();
    let mut req = request();
    req.stream = true;
    let pieces = Arc::new(AtomicUsize::new(0));
    let counter = pieces.clone();
    let on_text = move |_: &str| {
        counter.fetch_add(1, Ordering::SeqCst);
    };
    let answer = run(client.chat(&req, Some(&on_text))).unwrap();
    assert_eq!(answer.text, text);
    assert!(pieces.load(Ordering::SeqCst) > 3);
    assert!(answer.usage.completion_tokens > 0);
    assert_eq!(server.requests()[0]["stream_options"]["include_usage"], true);
}

#[test]
fn the_grammar_travels_in_the_dialects_field_and_unsupported_ones_are_refused() {
    let server = FakeLlm::script(vec![Reply::chat("x")]);
    let mut c = config(&server);
    c.dialect = Dialect::LlamaCpp;
    let mut req = request();
    req.constraint = Constraint::Gbnf("root ::= \"x\"".into());
    run(Client::new(c.clone()).unwrap().chat(&req, None)).unwrap();
    assert_eq!(server.requests()[0]["grammar"], "root ::= \"x\"");
    c.dialect = Dialect::OpenAi;
    let error = run(Client::new(c).unwrap().chat(&req, None)).unwrap_err();
    assert_eq!((error.kind, server.requests().len()), (ErrorKind::Request, 1));
}

#[test]
fn the_concurrency_limit_holds() {
    let in_flight = Arc::new(AtomicUsize::new(0));
    let peak = Arc::new(AtomicUsize::new(0));
    let (now, top) = (in_flight.clone(), peak.clone());
    let server = FakeLlm::start(move |_, _| {
        let n = now.fetch_add(1, Ordering::SeqCst) + 1;
        top.fetch_max(n, Ordering::SeqCst);
        std::thread::sleep(Duration::from_millis(100));
        now.fetch_sub(1, Ordering::SeqCst);
        Reply::chat("x")
    });
    let mut c = config(&server);
    c.concurrency = 2;
    let client = Client::new(c).unwrap();
    let rt = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
    rt.block_on(async {
        let tasks: Vec<_> = (0..6)
            .map(|_| {
                let client = client.clone();
                tokio::spawn(async move { client.chat(&request(), None).await })
            })
            .collect();
        for t in tasks {
            t.await.unwrap().unwrap();
        }
    });
    assert_eq!(peak.load(Ordering::SeqCst), 2);
    assert_eq!(client.usage().prompt_tokens, 600);
}
