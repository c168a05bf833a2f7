//! `tadslc explain CODE`: print a code's reference text from `spec/diagnostics.md`.

use crate::Status;
use tad_diagnostics::Code;

pub fn run(code: Option<&str>) -> Status {
    let Some(text) = code else {
        for code in Code::ALL {
            println!("{code}  {}", code.title());
        }
        return Status::Ok;
    };
    match Code::parse(text) {
        Some(code) => {
            println!("{}", code.reference().trim_start_matches("## "));
            Status::Ok
        }
        None => {
            eprintln!("error: `{text}` is not a TADSL diagnostic code");
            eprintln!("note: `tadslc explain` without a code lists them all");
            Status::Usage
        }
    }
}
