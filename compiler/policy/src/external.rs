//! An ego driven by any process: `external:CMD`, for stacks that are not in Rust or Python
//! (a ROS bridge, a C++ planner).
//!
//! The protocol is JSON lines over the process's standard input and output. For each
//! episode the command starts afresh (`sh -c CMD`, its standard error left to the user).
//! Each step it receives one line, the [`EgoView`]:
//!
//! ```json
//! {"obs":[0.1,-0.02,8.3,0],"speed":8.3,"desired_speed":8.3,"target":[6.0,0.2],"lookahead":6.0,
//!  "wheelbase":2.9,"leader":[14.2,5.0],"stop":null,"curve_speed":null,"dt":0.1,
//!  "around":[[14.9,0.1,-3.3,0,0,4.6,1.8]]}
//! ```
//!
//! (`leader` is `[gap m, speed m/s]` or `null`, `stop` metres or `null`, `curve_speed`
//! `null` where the route is straight, `around` the nearest actors, nearest first, each
//! `[x, y, vx, vy, yaw, length, width]` in the ego's frame relative to the ego) and answers one line, the action: `[accel, steer]`
//! (Gymnasium's two-number action) or `{"accel": A, "steer": S}`, accel in m/s², steer in
//! `[-1, 1]`, positive to the right. Everything it writes is untrusted: a line that is not
//! JSON or longer than 64 KiB, an action of another size or a number that is not finite, no
//! answer within the timeout (5 s by default), or the process ending, fails the policy with
//! a clear reason ([`EgoPolicy::failure`]); the runtime then ends the episode (`ego_failed`),
//! and the run goes on. The process is killed when the episode ends.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::Duration;

use crate::{Action, EgoPolicy, EgoView};

/// How long the process may take to answer a step, unless the spec says otherwise.
pub const TIMEOUT: Duration = Duration::from_secs(5);

/// The longest answer read, bytes.
const LINE: usize = 64 * 1024;

/// An ego driven by a process over JSON lines (see the module's header).
pub struct External {
    name: String,
    command: String,
    timeout: Duration,
    running: Option<Running>,
    failure: Option<String>,
}

/// The process of the current episode: its input, and the lines of its output.
struct Running {
    child: Child,
    input: ChildStdin,
    lines: Receiver<Result<String, String>>,
}

impl External {
    pub fn new(command: &str, timeout: Duration) -> External {
        External {
            name: format!("external:{command}"),
            command: command.to_string(),
            timeout,
            running: None,
            failure: None,
        }
    }

    fn start(&mut self) -> Result<(), String> {
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(&self.command)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| format!("cannot start `{}`: {e}", self.command))?;
        let (input, output) = match (child.stdin.take(), child.stdout.take()) {
            (Some(i), Some(o)) => (i, o),
            _ => return Err("the process has no standard input or output".into()),
        };
        // one line waits at most, of at most `LINE` bytes: a process that floods its output
        // holds no more memory than that
        let (send, lines) = std::sync::mpsc::sync_channel(1);
        std::thread::spawn(move || {
            let mut reader = BufReader::new(output);
            loop {
                let mut line = Vec::new();
                match (&mut reader).take(LINE as u64 + 1).read_until(b'\n', &mut line) {
                    Ok(0) | Err(_) => break,
                    Ok(_) => {}
                }
                let answer = if line.len() > LINE && !line.ends_with(b"\n") {
                    Err(format!("an answer longer than {LINE} bytes"))
                } else {
                    Ok(String::from_utf8_lossy(&line).trim_end().to_string())
                };
                let overlong = answer.is_err();
                if send.send(answer).is_err() || overlong {
                    break;
                }
            }
        });
        self.running = Some(Running { child, input, lines });
        Ok(())
    }

    fn stop(&mut self) {
        if let Some(mut running) = self.running.take() {
            let _ = running.child.kill();
            let _ = running.child.wait();
        }
    }

    /// One step over the protocol: the view out, the action back.
    fn exchange(&mut self, view: &EgoView) -> Result<Action, String> {
        if self.running.is_none() {
            self.start()?;
        }
        let timeout = self.timeout;
        let running = self.running.as_mut().expect("started above");
        let line = request(view) + "\n";
        running
            .input
            .write_all(line.as_bytes())
            .and_then(|()| running.input.flush())
            .map_err(|e| format!("cannot write to the process: {e}"))?;
        match running.lines.recv_timeout(timeout) {
            Ok(Ok(answer)) => action(&answer),
            Ok(Err(why)) => Err(why),
            Err(RecvTimeoutError::Timeout) => Err(format!("no action within {:.1} s", timeout.as_secs_f64())),
            Err(RecvTimeoutError::Disconnected) => {
                let status = running.child.wait().map(|s| s.to_string()).unwrap_or_else(|e| e.to_string());
                Err(format!("the process ended ({status}) without an action"))
            }
        }
    }
}

impl Drop for External {
    fn drop(&mut self) {
        self.stop();
    }
}

impl EgoPolicy for External {
    fn name(&self) -> &str {
        &self.name
    }

    fn reset(&mut self) {
        self.stop();
        self.failure = None;
    }

    fn act(&mut self, view: &EgoView) -> Action {
        if self.failure.is_some() {
            return Action::default();
        }
        match self.exchange(view) {
            Ok(action) => action,
            Err(why) => {
                self.failure = Some(why);
                self.stop();
                Action::default()
            }
        }
    }

    fn failure(&self) -> Option<&str> {
        self.failure.as_deref()
    }
}

/// A number as JSON, `null` when it is not finite.
fn number(x: f64) -> String {
    if x.is_finite() { format!("{x}") } else { "null".into() }
}

/// The view as one JSON line.
fn request(view: &EgoView) -> String {
    let pair = |p: Option<(f64, f64)>| p.map_or("null".to_string(), |(a, b)| format!("[{},{}]", number(a), number(b)));
    let obs: Vec<String> = view.obs.iter().map(|x| number(*x)).collect();
    let around: Vec<String> = view
        .around
        .iter()
        .flatten()
        .map(|n| {
            let values = [n.position[0], n.position[1], n.velocity[0], n.velocity[1], n.yaw, n.size[0], n.size[1]];
            format!("[{}]", values.map(number).join(","))
        })
        .collect();
    format!(
        "{{\"obs\":[{}],\"speed\":{},\"desired_speed\":{},\"target\":[{},{}],\"lookahead\":{},\"wheelbase\":{},\"leader\":{},\"stop\":{},\"curve_speed\":{},\"dt\":{},\"around\":[{}]}}",
        obs.join(","),
        number(view.speed),
        number(view.desired_speed),
        number(view.target[0]),
        number(view.target[1]),
        number(view.lookahead),
        number(view.wheelbase),
        pair(view.leader),
        view.stop.map_or("null".into(), number),
        number(view.curve_speed),
        number(view.dt),
        around.join(","),
    )
}

/// The action a line states, or why it states none.
fn action(line: &str) -> Result<Action, String> {
    let shown: String = line.chars().take(80).collect();
    let value: serde_json::Value =
        serde_json::from_str(line.trim()).map_err(|e| format!("the answer `{shown}` is not JSON ({e})"))?;
    let (accel, steer) = match &value {
        serde_json::Value::Array(items) if items.len() == 2 => (items[0].as_f64(), items[1].as_f64()),
        serde_json::Value::Array(items) => {
            return Err(format!("an action is 2 numbers, [accel, steer]; the answer has {}", items.len()));
        }
        serde_json::Value::Object(map) => {
            (map.get("accel").and_then(serde_json::Value::as_f64), map.get("steer").and_then(serde_json::Value::as_f64))
        }
        _ => (None, None),
    };
    match (accel, steer) {
        (Some(accel), Some(steer)) if accel.is_finite() && steer.is_finite() => {
            Ok(Action { accel, steer: steer.clamp(-1.0, 1.0) })
        }
        _ => Err(format!("the answer `{shown}` is not an action: [accel, steer] or {{\"accel\": A, \"steer\": S}}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> EgoView {
        EgoView {
            obs: [0.1, -0.02, 8.0, 0.0],
            speed: 8.0,
            desired_speed: 8.0,
            target: [6.0, 0.0],
            lookahead: 6.0,
            wheelbase: 2.9,
            leader: Some((14.0, 5.0)),
            stop: None,
            curve_speed: f64::INFINITY,
            dt: 0.1,
            around: [None; crate::NEAR],
        }
    }

    /// `steps` actions of `command` with `timeout` (a well-behaved process gets the default:
    /// a loaded machine may take a while to start a shell).
    fn drive(command: &str, steps: usize, timeout: Duration) -> (Vec<Action>, Option<String>) {
        let mut ego = External::new(command, timeout);
        ego.reset();
        let actions = (0..steps).map(|_| ego.act(&view())).collect();
        (actions, ego.failure().map(String::from))
    }

    #[test]
    fn a_process_drives_over_json_lines() {
        let (actions, failure) = drive("while read line; do echo '[1.5, -0.25]'; done", 3, TIMEOUT);
        assert_eq!(failure, None);
        assert_eq!(actions, vec![Action { accel: 1.5, steer: -0.25 }; 3]);
        // the object form, and the view it received, echoed back as its speed
        let command = r#"while read line; do s=$(echo "$line" | sed 's/.*"speed":\([0-9.]*\).*/\1/'); echo "{\"accel\": $s, \"steer\": 2}"; done"#;
        let (actions, failure) = drive(command, 2, TIMEOUT);
        assert_eq!(failure, None);
        assert_eq!(actions[0], Action { accel: 8.0, steer: 1.0 }, "steer clamped to 1");
    }

    #[test]
    fn a_misbehaving_process_fails_the_policy_with_a_reason_and_never_hangs() {
        let cases = [
            ("while read line; do echo 'full throttle'; done", "is not JSON"),
            ("while read line; do echo '[1, 0, 3]'; done", "an action is 2 numbers"),
            ("while read line; do echo '{\"accel\": \"fast\"}'; done", "is not an action"),
            ("sleep 10", "no action within 0.5 s"),
            ("read line; exit 3", "the process ended"),
            ("/nonexistent/driver", "the process"),
            ("read line; yes 1 | tr -d '\\n'", "an answer longer than 65536 bytes"),
        ];
        for (command, reason) in cases {
            // the silent process is timed out quickly; the others fail on what they say
            let timeout = if command.starts_with("sleep") { Duration::from_millis(500) } else { TIMEOUT };
            let started = std::time::Instant::now();
            let (actions, failure) = drive(command, 3, timeout);
            let failure = failure.unwrap_or_else(|| panic!("`{command}` did not fail"));
            assert!(failure.contains(reason), "`{command}`: {failure}");
            assert_eq!(actions[1], Action::default(), "nothing is asked of a failed process");
            assert!(started.elapsed() < timeout + Duration::from_millis(2500), "`{command}` held the run");
        }
    }
}
