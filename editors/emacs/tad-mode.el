;;; tad-mode.el --- Major mode for TAD traffic scenarios (TADSL) -*- lexical-binding: t; -*-

;; Version: 0.1.0
;; Package-Requires: ((emacs "27.1"))
;; Keywords: languages

;;; Commentary:

;; Font-lock, comments and indentation for `.tad' files, and the language server
;; `tadslc lsp' registered with eglot (Emacs 29 has eglot built in):
;;
;;   (add-to-list 'load-path "/path/to/tadsl/editors/emacs")
;;   (require 'tad-mode)
;;   (add-hook 'tad-mode-hook #'eglot-ensure)
;;
;; Checker settings go to the server through eglot's workspace configuration:
;;
;;   (setq-default eglot-workspace-configuration '(:tadsl (:profile "auto")))

;;; Code:

(defgroup tad nil
  "TAD traffic scenarios."
  :group 'languages)

(defcustom tad-indent-offset 2
  "Indentation of a block's contents, as `tadslc fmt' writes it."
  :type 'integer
  :group 'tad)

(defcustom tad-server-command '("tadslc" "lsp")
  "The language server's command line."
  :type '(repeat string)
  :group 'tad)

(defvar tad-mode-syntax-table
  (let ((table (make-syntax-table)))
    (modify-syntax-entry ?/ ". 12" table)
    (modify-syntax-entry ?\n ">" table)
    (modify-syntax-entry ?_ "_" table)
    (modify-syntax-entry ?\" "\"" table)
    (modify-syntax-entry ?\\ "\\" table)
    (modify-syntax-entry ?{ "(}" table)
    (modify-syntax-entry ?} "){" table)
    (modify-syntax-entry ?\[ "(]" table)
    (modify-syntax-entry ?\] ")[" table)
    table)
  "Syntax table for `tad-mode'.")

(defconst tad-font-lock-keywords
  `(("^\\s-*\\(use\\)\\s-+\\([A-Za-z_][A-Za-z0-9_.]*\\)"
     (1 font-lock-keyword-face) (2 font-lock-constant-face))
    ("\\_<\\(scenario\\)\\s-+\\([A-Za-z_][A-Za-z0-9_]*\\)"
     (1 font-lock-keyword-face) (2 font-lock-function-name-face))
    ("\\_<\\(actor\\)\\s-+\\([A-Za-z_][A-Za-z0-9_]*\\)\\s-*:\\s-*\\(?:[0-9.]+\\s-+\\)?\\([A-Za-z_][A-Za-z0-9_]*\\)?"
     (1 font-lock-keyword-face) (2 font-lock-variable-name-face) (3 font-lock-type-face nil t))
    ("^\\([A-Za-z_][A-Za-z0-9_]*\\)\\s-+\\([A-Za-z_][A-Za-z0-9_]*\\)\\s-*\\(?:{\\|$\\)"
     (1 font-lock-keyword-face) (2 font-lock-type-face))
    ("\\_<\\([A-Za-z_][A-Za-z0-9_]*\\)\\s-*{" 1 font-lock-preprocessor-face)
    ("\\_<\\([A-Za-z_][A-Za-z0-9_]*\\)\\s-*:" 1 font-lock-variable-name-face)
    ("\\_<\\(of\\)\\s-+\\([A-Za-z_][A-Za-z0-9_]*\\)"
     (1 font-lock-keyword-face) (2 font-lock-variable-name-face))
    ("\\_<\\(unspecified\\|yes\\|no\\)\\_>" . font-lock-constant-face)
    ("-?[0-9]+\\(?:\\.[0-9]+\\)?\\s-*\\(km/h\\|mph\\|m/s\\|m\\|s\\)\\_>" 1 font-lock-builtin-face))
  "Highlighting for `tad-mode'.")

(defun tad-indent-line ()
  "Indent the current line by the depth of the braces around it."
  (interactive)
  (let ((depth (save-excursion (car (syntax-ppss (line-beginning-position))))))
    (save-excursion
      (back-to-indentation)
      (when (looking-at "[]}]")
        (setq depth (max 0 (1- depth)))))
    (indent-line-to (* depth tad-indent-offset))))

;;;###autoload
(define-derived-mode tad-mode prog-mode "TAD"
  "Major mode for TAD traffic scenarios."
  :syntax-table tad-mode-syntax-table
  (setq-local comment-start "// ")
  (setq-local comment-end "")
  (setq-local comment-start-skip "//+\\s-*")
  (setq-local indent-line-function #'tad-indent-line)
  (setq-local indent-tabs-mode nil)
  (setq-local font-lock-defaults '(tad-font-lock-keywords)))

;;;###autoload
(add-to-list 'auto-mode-alist '("\\.tad\\'" . tad-mode))

(defvar eglot-server-programs)
(with-eval-after-load 'eglot
  (add-to-list 'eglot-server-programs `(tad-mode . ,tad-server-command)))

(provide 'tad-mode)
;;; tad-mode.el ends here
