//! `tadslc synth`: a driving video (or a directory of frames) to validated scenarios
//! (`tad_frontend::synth`): a frame every 15 s described, translated, checked, repaired;
//! resumable, `--shard I/N` for job arrays, Ctrl-C finishes the frames under way.

use std::path::PathBuf;

use tad_frontend::Summary;
use tad_frontend::backend;

use crate::llm::{LlmArgs, report_summary};
use crate::output::CliError;
use crate::{Status, errln};

/// `tadslc synth`'s arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The video
    #[arg(long, value_name = "FILE", conflicts_with = "frames", required_unless_present = "frames")]
    pub video: Option<PathBuf>,
    /// A directory of frames (.jpg, .png) instead of a video
    #[arg(long, value_name = "DIR")]
    pub frames: Option<PathBuf>,
    /// The region the video was recorded in
    #[arg(long, value_name = "REGION", value_parser = tad_db::region)]
    pub region: String,
    /// The output directory
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Seconds between frames
    #[arg(long, value_name = "S", default_value_t = 15.0)]
    pub every: f64,
    /// Do only the frames of shard i of n (`0/4`)
    #[arg(long, value_name = "I/N", default_value = "0/1")]
    pub shard: tad_base::Shard,
    /// Frames under way at once
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub jobs: usize,
    /// How often an incomplete scenario's frame is described again
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub max_refinements: u32,
    #[command(flatten)]
    pub llm: LlmArgs,
}

pub fn run(s: &Args) -> Result<Status, CliError> {
    let args = &s.llm;
    let input = match (s.video.as_deref(), s.frames.as_deref()) {
        (Some(v), None) => tad_frontend::synth::Input::Video(v.to_path_buf()),
        (None, Some(d)) => tad_frontend::synth::Input::Frames(d.to_path_buf()),
        _ => return Err(CliError::usage("give either --video FILE or --frames DIR")),
    };
    // the frames are images: refuse the text-only local model before any frame is taken
    if !args.names_server().map_err(CliError::usage)? {
        return Err(CliError::usage(
            "synth describes video frames, and the local model reads text only: configure a multimodal server \
             (TADSL_LLM_BASE_URL and TADSL_LLM_MODEL, or --base-url and --model, or a TOML file with --llm-config)",
        ));
    }
    let backend = args.open(s.jobs.max(1)).map_err(CliError::usage)?;
    let checker = backend::checker(Some(&s.region)).map_err(CliError::usage)?;
    let constraint = backend.constraint_for(args.constrained(&backend), Some(&s.region)).map_err(CliError::usage)?;
    let session = args.session(&backend, &checker, constraint, 0.0);
    let spec = tad_frontend::synth::Spec {
        input,
        region: s.region.to_string(),
        out: s.out.to_path_buf(),
        every: s.every,
        shard: s.shard,
        jobs: s.jobs,
        max_refinements: s.max_refinements,
        model: backend.chat().label(),
        ffmpeg: std::env::var("TADSL_FFMPEG").unwrap_or_else(|_| "ffmpeg".into()),
        ffprobe: std::env::var("TADSL_FFPROBE").unwrap_or_else(|_| "ffprobe".into()),
    };
    std::fs::create_dir_all(&s.out)
        .map_err(|e| CliError::usage(format!("cannot create `{}`: {e}", s.out.display())))?;
    let stop = crate::output::on_interrupt("frames");
    let runtime = backend::runtime().map_err(CliError::usage)?;
    let bar = crate::output::progress(0, "frames");
    let mut summary = Summary::default();
    let mut failed = 0usize;
    let report = runtime
        .block_on(tad_frontend::synth::run(
            &session,
            &spec,
            &stop,
            &mut |record| {
                if record.status == "failed" {
                    failed += 1;
                    bar.println(format!("{}: {}", record.frame, record.reasons.join("; ")));
                } else {
                    summary.add(&record.outcome);
                }
                if bar.length() == Some(0) {
                    bar.set_length(1);
                }
                bar.inc(1);
                bar.set_message(record.status.to_string());
            },
            &mut |_| {},
        ))
        .map_err(|e| CliError::usage(e.0))?;
    bar.finish_and_clear();
    errln!(
        "{} in this shard: {} done before, {} now, {} failed (rerun to retry)",
        crate::plural(report.total, "frame"),
        report.done_before,
        report.records.len() - failed,
        failed
    )?;
    report_summary(
        Some(&s.out),
        &summary,
        serde_json::json!({ "region": s.region, "model": backend.chat().label(), "shard": s.shard.to_string() }),
    )?;
    if report.interrupted {
        errln!("interrupted: run the same command again to continue")?;
        return Ok(Status::Failed);
    }
    Ok(if failed > 0 && failed == report.records.len() { Status::Unreachable } else { Status::Ok })
}
