//! Corpora on the command line (`tad_eval::corpus`): the paths that cannot be read are
//! reported (status 2), the files that do not count noted once, and a corpus where none
//! counts is an error. What `stats`, `compare`, `fit`, `sft-export`, `gen` and `eval` read.

use std::path::PathBuf;

use tad_eval::Corpus;
use tad_stats::Features;

use crate::output::CliError;
use crate::{Status, errln};

/// Every scenario under `paths` that counts, as one corpus, and the status reading it
/// reached: the paths that could not be read are reported and make it 2.
pub fn read(paths: &[PathBuf]) -> Result<(Corpus, Status), CliError> {
    let (corpus, errors) = tad_eval::corpus::read(paths);
    for e in &errors {
        errln!("error: {e}")?;
    }
    Ok((corpus, if errors.is_empty() { Status::Ok } else { Status::Usage }))
}

/// [`read`], then [`counted`].
pub fn load(paths: &[PathBuf]) -> Result<(Corpus, Status), CliError> {
    let (corpus, status) = read(paths)?;
    Ok((counted(corpus)?, status))
}

/// `corpus`, after a note on its files that did not count; a corpus where none did is an
/// error.
pub fn counted(corpus: Corpus) -> Result<Corpus, CliError> {
    if let Some(note) = corpus.skipped_note() {
        errln!("note: {note}")?;
    }
    if corpus.items.is_empty() {
        return Err(CliError::usage(format!("corpus `{}` has no valid scenario", corpus.name)));
    }
    Ok(corpus)
}

/// The scenarios' features.
pub fn features(corpus: &Corpus) -> Vec<Features> {
    corpus.items.iter().map(|i| i.features.clone()).collect()
}
