//! From a driving video (or a directory of frames) to validated scenarios, one per frame.
//!
//! ```text
//! video ──ffprobe: duration──▶ times 0, 15, 30 s, ... ──shard i/n──▶ not in the manifest yet
//!   ──ffmpeg: one JPEG at t (in memory)──▶ describe (image + prompt) ──▶ description
//!   ──translate (session)──▶ complete / incomplete / non-scenario / invalid
//!   incomplete: describe again with the refinement requests appended (bounded), translate again
//!   ──▶ NAME_tSSSS.tad (complete, incomplete), rejected/ (invalid), a manifest line each
//! ```
//!
//! Resumable: a frame with a manifest line is done and never redone; files are written
//! atomically before their manifest line, so a killed run leaves at worst a file a rerun
//! rewrites. An interrupt stops starting frames and lets those under way finish.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use futures_util::StreamExt;
use serde::Serialize;
use tad_llm::{Message, Part, Role};

use crate::session::{Outcome, Round, Session};
use crate::{Provenance, prompt, store};

/// Where frames come from.
#[derive(Clone, Debug)]
pub enum Input {
    Video(PathBuf),
    Frames(PathBuf),
}

pub struct Spec {
    pub input: Input,
    pub region: String,
    pub out: PathBuf,
    /// Seconds between frames of a video.
    pub every: f64,
    /// This run does the frames whose index the shard takes.
    pub shard: tad_base::Shard,
    pub jobs: usize,
    /// How often an incomplete scenario's frame is described again.
    pub max_refinements: u32,
    pub model: String,
    pub ffmpeg: String,
    pub ffprobe: String,
}

/// One frame to do.
#[derive(Clone, Debug)]
pub struct Frame {
    pub index: usize,
    pub id: String,
    pub time_s: Option<f64>,
    pub image: Option<PathBuf>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Record {
    pub frame: String,
    pub index: usize,
    pub video: Option<String>,
    pub time_s: Option<f64>,
    pub file: Option<String>,
    pub status: &'static str,
    /// Why a frame gave no scenario: the non-scenario's missing facts, the errors left.
    pub reasons: Vec<String>,
    pub description: Option<String>,
    pub refinements: u32,
    pub model: String,
    pub prompts: [&'static str; 2],
    #[serde(flatten)]
    pub outcome: Outcome,
}

#[derive(Debug)]
pub struct Error(pub String);

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

fn io(what: &str, e: std::io::Error) -> Error {
    Error(format!("{what}: {e}"))
}

/// The manifest of this shard.
pub fn manifest_path(spec: &Spec) -> PathBuf {
    spec.out.join(spec.shard.file_name("manifest", "jsonl"))
}

/// Every frame of the input, in order.
pub fn frames(spec: &Spec) -> Result<Vec<Frame>, Error> {
    match &spec.input {
        Input::Video(video) => {
            let duration = probe_duration(&spec.ffprobe, video)?;
            let stem =
                store::file_stem(&video.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
            let every = if spec.every.is_finite() && spec.every > 0.0 { spec.every } else { 15.0 };
            let count = ((duration / every).ceil() as usize).clamp(1, 1_000_000);
            Ok((0..count)
                .map(|i| {
                    let t = i as f64 * every;
                    Frame { index: i, id: format!("{stem}_t{:05}", t.round() as u64), time_s: Some(t), image: None }
                })
                .collect())
        }
        Input::Frames(dir) => {
            let mut images: Vec<PathBuf> = std::fs::read_dir(dir)
                .map_err(|e| io(&format!("cannot read `{}`", dir.display()), e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    let ext = p.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
                    matches!(ext.as_str(), "jpg" | "jpeg" | "png")
                })
                .collect();
            images.sort();
            if images.is_empty() {
                return Err(Error(format!("{} holds no .jpg or .png frames", dir.display())));
            }
            Ok(images
                .into_iter()
                .enumerate()
                .map(|(i, p)| {
                    let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
                    Frame { index: i, id: store::file_stem(&stem), time_s: None, image: Some(p) }
                })
                .collect())
        }
    }
}

fn probe_duration(ffprobe: &str, video: &Path) -> Result<f64, Error> {
    let output = Command::new(ffprobe)
        .args(["-v", "error", "-show_entries", "format=duration", "-of", "default=noprint_wrappers=1:nokey=1"])
        .arg(video)
        .output()
        .map_err(|e| Error(format!("cannot run {ffprobe} (install ffmpeg): {e}")))?;
    let text = String::from_utf8_lossy(&output.stdout);
    match text.trim().parse::<f64>() {
        Ok(d) if output.status.success() && d.is_finite() && d > 0.0 => Ok(d),
        _ => Err(Error(format!(
            "{} is not a video ffprobe can read: {}",
            video.display(),
            String::from_utf8_lossy(&output.stderr).trim()
        ))),
    }
}

/// The frame at `t` seconds as a JPEG at most 768 pixels wide, without temporary files.
fn grab(ffmpeg: &str, video: &Path, t: f64) -> Result<Vec<u8>, Error> {
    let output = Command::new(ffmpeg)
        .args(["-v", "error", "-ss", &format!("{t:.3}"), "-i"])
        .arg(video)
        .args([
            "-frames:v",
            "1",
            "-vf",
            "scale='min(768,iw)':-2",
            "-q:v",
            "4",
            "-f",
            "image2",
            "-c:v",
            "mjpeg",
            "pipe:1",
        ])
        .output()
        .map_err(|e| Error(format!("cannot run {ffmpeg} (install ffmpeg): {e}")))?;
    if !output.status.success() || output.stdout.is_empty() {
        return Err(Error(format!(
            "ffmpeg took no frame at {t:.1} s: {}",
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    Ok(output.stdout)
}

fn image(spec: &Spec, frame: &Frame) -> Result<(String, Vec<u8>), Error> {
    match (&spec.input, &frame.image) {
        (_, Some(path)) => {
            let bytes = std::fs::read(path).map_err(|e| io(&format!("cannot read `{}`", path.display()), e))?;
            let png = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
            Ok((if png { "image/png" } else { "image/jpeg" }.into(), bytes))
        }
        (Input::Video(video), None) => {
            Ok(("image/jpeg".into(), grab(&spec.ffmpeg, video, frame.time_s.unwrap_or(0.0))?))
        }
        (Input::Frames(_), None) => Err(Error("a frame without an image".into())),
    }
}

/// The report inside `<DESCRIPTION>` tags, else the answer without its analysis.
pub fn description_of(answer: &str) -> String {
    let tagged = |open: &str, close: &str| {
        let start = answer.find(open)? + open.len();
        let end = answer[start..].find(close).map(|e| start + e).unwrap_or(answer.len());
        Some(answer[start..end].trim().to_string())
    };
    if let Some(d) = tagged("<DESCRIPTION>", "</DESCRIPTION>") {
        return d;
    }
    let mut text = answer.to_string();
    if let (Some(a), Some(b)) = (text.find("<ANALYSIS>"), text.find("</ANALYSIS>"))
        && b > a
    {
        text.replace_range(a..b + "</ANALYSIS>".len(), "");
    }
    text.trim().to_string()
}

/// What the run did.
#[derive(Debug, Default)]
pub struct Report {
    pub done_before: usize,
    pub records: Vec<Record>,
    pub interrupted: bool,
    pub total: usize,
}

/// Runs the pipeline. `stop` is checked before each frame starts; `on_record` sees each
/// frame's record as it is written; `on_round` each round of every session.
pub async fn run(
    session: &Session<'_>,
    spec: &Spec,
    stop: &AtomicBool,
    on_record: &mut dyn FnMut(&Record),
    on_round: &mut dyn FnMut(&Round),
) -> Result<Report, Error> {
    let all = frames(spec)?;
    let manifest = manifest_path(spec);
    let done: std::collections::HashSet<String> =
        store::read_jsonl(&manifest).iter().filter_map(|r| r["frame"].as_str().map(String::from)).collect();
    let mine: Vec<Frame> = all.into_iter().filter(|f| spec.shard.takes(f.index)).collect();
    let total = mine.len();
    let todo: Vec<Frame> = mine.into_iter().filter(|f| !done.contains(&f.id)).collect();
    let mut report = Report { done_before: total - todo.len(), total, ..Default::default() };
    let mut writer = store::Jsonl::append(&manifest).map_err(|e| io("cannot write the manifest", e))?;
    let mut transcript = store::Jsonl::append(&manifest.with_extension("transcript.jsonl"))
        .map_err(|e| io("cannot write the transcript", e))?;
    let rounds = Mutex::new(Vec::<Round>::new());
    let results = futures_util::stream::iter(todo)
        .take_while(|_| {
            let go = !stop.load(Ordering::SeqCst);
            async move { go }
        })
        .map(|frame| {
            let rounds = &rounds;
            async move {
                let record = one(session, spec, &frame, &mut |r| rounds.lock().unwrap().push(r.clone())).await;
                (frame, record)
            }
        })
        .buffer_unordered(spec.jobs.max(1));
    let mut results = std::pin::pin!(results);
    while let Some((frame, record)) = results.next().await {
        for r in rounds.lock().unwrap().drain(..) {
            transcript.write(&r).map_err(|e| io("cannot write the transcript", e))?;
            on_round(&r);
        }
        let record = match record {
            Ok(record) => record,
            Err(e) => {
                // a frame that failed is reported and left for the next run
                report.records.push(failed(spec, &frame, e.0.clone()));
                on_record(report.records.last().expect("just pushed"));
                continue;
            }
        };
        writer.write(&record).map_err(|e| io("cannot write the manifest", e))?;
        on_record(&record);
        report.records.push(record);
    }
    report.interrupted = stop.load(Ordering::SeqCst);
    Ok(report)
}

fn failed(spec: &Spec, frame: &Frame, reason: String) -> Record {
    Record {
        frame: frame.id.clone(),
        index: frame.index,
        video: video_name(spec),
        time_s: frame.time_s,
        file: None,
        status: "failed",
        reasons: vec![reason],
        description: None,
        refinements: 0,
        model: spec.model.clone(),
        prompts: [prompt::DESCRIBE.id, prompt::TRANSLATE.id],
        outcome: Outcome::default(),
    }
}

fn video_name(spec: &Spec) -> Option<String> {
    match &spec.input {
        Input::Video(v) => v.file_name().map(|n| n.to_string_lossy().into_owned()),
        Input::Frames(_) => None,
    }
}

/// One frame: describe, translate, refine; the file written; its record.
async fn one(
    session: &Session<'_>,
    spec: &Spec,
    frame: &Frame,
    on_round: &mut dyn FnMut(&Round),
) -> Result<Record, Error> {
    let (mime, bytes) = image(spec, frame)?;
    let region_clause = format!(" (recorded in the region {})", spec.region);
    let example = crate::prompt_example().0;
    let mut describe =
        prompt::DESCRIBE.messages(&[("region_clause", &region_clause), ("example_description", &example)]);
    if let Some(user) = describe.last_mut() {
        user.parts.push(Part::Image { mime, bytes });
    }
    let describer = Session { constraint: tad_llm::Constraint::None, ..session.with_seed(frame.index as u64) };
    let mut refinements = 0;
    let mut answer = describer.describe(&frame.id, describe.clone(), on_round).await.map_err(Error)?;
    let (mut description, mut outcome);
    loop {
        description = description_of(&answer);
        let messages = crate::translate_messages(&description, session.checker);
        outcome = session.run(&frame.id, messages, prompt::TRANSLATE.id, on_round).await;
        if outcome.class != Some("incomplete") || refinements >= spec.max_refinements || outcome.stopped.is_some() {
            break;
        }
        refinements += 1;
        let requests = outcome.requests.iter().map(|r| format!("- {r}")).collect::<Vec<_>>().join("\n");
        let mut again = describe.clone();
        again.push(Message::text(Role::Assistant, answer.clone()));
        again.push(Message::text(Role::User, prompt::REFINE_DESCRIPTION.render(&[("requests", &requests)]).user));
        answer = describer.describe(&frame.id, again, on_round).await.map_err(Error)?;
    }
    if let Some(stopped) = &outcome.stopped
        && outcome.program.is_none()
    {
        return Err(Error(stopped.clone()));
    }
    let status = outcome.class.unwrap_or("no_program");
    let reasons = match status {
        "complete" => Vec::new(),
        "incomplete" => outcome.requests.clone(),
        _ => outcome.diagnostics.clone(),
    };
    let mut file = None;
    if let (Some(program), true) = (&outcome.program, matches!(status, "complete" | "incomplete" | "invalid")) {
        let provenance = Provenance {
            comments: vec![format!(
                "synthesised by tadslc {} from {} with model {}, {} round{}, {} refinement{}, prompts {} and {}",
                env!("CARGO_PKG_VERSION"),
                match (video_name(spec), frame.time_s) {
                    (Some(v), Some(t)) => format!("{v} at {t:.0} s"),
                    _ => format!("frame {}", frame.id),
                },
                spec.model,
                outcome.rounds,
                if outcome.rounds == 1 { "" } else { "s" },
                refinements,
                if refinements == 1 { "" } else { "s" },
                prompt::DESCRIBE.id,
                prompt::TRANSLATE.id,
            )]
            .into_iter()
            .chain(outcome.suggested_line())
            .collect(),
            video: video_name(spec),
            time_s: frame.time_s,
            frame: frame.time_s.is_none().then_some(frame.index as u64),
            region: Some(spec.region.clone()),
            description: Some(description.clone()),
        };
        let dir = if status == "invalid" { spec.out.join("rejected") } else { spec.out.clone() };
        let path = store::inside(&dir, &frame.id, "tad");
        store::write_atomic(&path, crate::with_provenance(program, &provenance).as_bytes())
            .map_err(|e| io(&format!("cannot write `{}`", path.display()), e))?;
        file = Some(path.display().to_string());
    }
    Ok(Record {
        frame: frame.id.clone(),
        index: frame.index,
        video: video_name(spec),
        time_s: frame.time_s,
        file,
        status,
        reasons,
        description: Some(description),
        refinements,
        model: spec.model.clone(),
        prompts: [prompt::DESCRIBE.id, prompt::TRANSLATE.id],
        outcome,
    })
}
