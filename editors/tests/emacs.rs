//! The Emacs package (`editors/emacs/tad-mode.el`) in a real Emacs, in batch mode: it
//! byte-compiles without warnings; a `.tad` file opens in `tad-mode` with keywords, keys and
//! units highlighted; indentation gives `tadslc fmt`'s layout; and loading eglot registers
//! `tadslc lsp` for the mode.

use std::process::Command;

fn emacs() -> Option<std::path::PathBuf> {
    tad_editors::tool("emacs")
}

fn batch(emacs: &std::path::Path, program: &str) -> (bool, String) {
    let dir = tad_editors::dir().join("emacs");
    let output = Command::new(emacs)
        .args(["--batch", "-Q", "-L"])
        .arg(&dir)
        .args(["--eval", program])
        .env("HOME", std::env::temp_dir())
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    (output.status.success(), text)
}

#[test]
fn the_mode_byte_compiles_cleanly() {
    let Some(emacs) = emacs() else { return };
    let dir = std::env::temp_dir().join(format!("tad-emacs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let copy = dir.join("tad-mode.el");
    std::fs::copy(tad_editors::dir().join("emacs/tad-mode.el"), &copy).unwrap();
    let program = format!(
        "(progn (setq byte-compile-error-on-warn t) (unless (byte-compile-file \"{}\") (kill-emacs 1)))",
        copy.display()
    );
    let (ok, text) = batch(&emacs, &program);
    std::fs::remove_dir_all(&dir).ok();
    assert!(ok, "{text}");
}

#[test]
fn a_scenario_is_highlighted_and_indented() {
    let Some(emacs) = emacs() else { return };
    let example = tad_editors::repo().join("examples/safety/right_turn.tad");
    let program = format!(
        r#"(progn
  (require 'tad-mode)
  (find-file "{}")
  (unless (eq major-mode 'tad-mode) (princ "not tad-mode\n") (kill-emacs 1))
  (font-lock-ensure)
  (dolist (check '(("scenario right_turn" 0 font-lock-keyword-face)
                   ("weather: clear" 0 font-lock-variable-name-face)
                   ("speed: 12 km/h" 10 font-lock-builtin-face)
                   ("description: \"\"\"" 14 font-lock-string-face)
                   ("// ChatScene" 3 font-lock-comment-face)))
    (goto-char (point-min))
    (search-forward (car check))
    (let ((face (get-text-property (+ (match-beginning 0) (cadr check)) 'face)))
      (unless (eq face (car (cddr check)))
        (princ (format "%s has %s\n" (car check) face)) (kill-emacs 1))))
  (with-temp-buffer
    (insert "scenario demo {{\nroad {{\nlanes: 2\n    }}\n  actor a: car {{\n speed: 3 m/s\n}}\n}}\n")
    (tad-mode)
    (indent-region (point-min) (point-max))
    (unless (string= (buffer-string) "scenario demo {{\n  road {{\n    lanes: 2\n  }}\n  actor a: car {{\n    speed: 3 m/s\n  }}\n}}\n")
      (princ (buffer-string)) (kill-emacs 1)))
  (defvar eglot-server-programs nil)
  (provide 'eglot)
  (unless (equal (alist-get 'tad-mode eglot-server-programs) '("tadslc" "lsp"))
    (princ (format "eglot: %S\n" eglot-server-programs)) (kill-emacs 1))
  (princ "PASS\n"))"#,
        example.display()
    );
    let (ok, text) = batch(&emacs, &program);
    assert!(ok && text.contains("PASS"), "{text}");
}
