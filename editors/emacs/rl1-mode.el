;;; rl1-mode.el --- Major mode for RL/I robot programs (.rob)  -*- lexical-binding: t; -*-

;; Version: 0.1.0
;; Package-Requires: ((emacs "26.1"))
;; Keywords: languages
;; SPDX-License-Identifier: MIT

;;; Commentary:

;; RL/I is the robot language of Sugii et al. (1997).  This mode highlights the same
;; classes as the VS Code grammar (editors/vscode/syntaxes/rl1.tmLanguage.json):
;; comments, labels, jump targets, conditional jumps, built-in calls and their
;; selectors, variables (the reserved s-z apart), constants, operators and
;; separators, and marks what the compiler would reject.  Diagnostics, hover and
;; completion come from the rl1-lsp language server through eglot (see README.md).

;;; Code:

(defgroup rl1 nil
  "Editing RL/I robot programs."
  :group 'languages
  :prefix "rl1-")

(defconst rl1-mnemonics
  '("END" "FRE" "HLD" "ORG" "MVI" "MOV" "STR" "STL" "STX" "ROT" "TRC" "TIM"
    "KYC" "KYO" "SCN" "IMG" "CAM" "ULT" "LMP" "INP" "OUT" "FZO" "FZI")
  "The built-in functions of RL/I (the paper's Tables 1-3).")

(defface rl1-reserved-variable-face
  '((t :inherit font-lock-variable-name-face :weight bold))
  "Face for the reserved variables s-z, which sensing calls overwrite."
  :group 'rl1)

;; font-lock-operator-face and font-lock-delimiter-face exist from Emacs 29 on.
(defface rl1-operator-face
  `((t :inherit ,(if (facep 'font-lock-operator-face) 'font-lock-operator-face 'default)))
  "Face for the operators + - & | ^ < > = ++ --."
  :group 'rl1)

(defface rl1-separator-face
  `((t :inherit ,(if (facep 'font-lock-delimiter-face) 'font-lock-delimiter-face 'default)))
  "Face for the statement separator ; and the argument separator ,."
  :group 'rl1)

(defvar rl1-mode-syntax-table
  (let ((table (make-syntax-table)))
    (modify-syntax-entry ?' "<" table)
    (modify-syntax-entry ?\n ">" table)
    (modify-syntax-entry ?\r ">" table)
    (modify-syntax-entry ?\" "." table)   ; RL/I has no strings
    (modify-syntax-entry ?@ "w" table)    ; @ is a variable
    (modify-syntax-entry ?$ "_" table)
    (dolist (char '(?: ?# ?? ?- ?+ ?& ?| ?^ ?< ?> ?= ?\; ?,))
      (modify-syntax-entry char "." table))
    table)
  "Syntax table for `rl1-mode': `'' starts a comment that runs to the line end.")

(defconst rl1--known-call-regexp
  (concat "(\\s-*\\(" (regexp-opt rl1-mnemonics) "\\)\\(?:[^A-Za-z0-9@]\\|$\\)")
  "A call of a built-in, to match with case folding.
The compiler reads mnemonics in any letter case.")

(defun rl1--match-known-call (limit)
  "Find the next built-in call before LIMIT, in any letter case."
  (let ((case-fold-search t))
    (re-search-forward rl1--known-call-regexp limit t)))

(defun rl1--match-selector (limit)
  "Find the next selector of (CAM x) or (ULT x) before LIMIT.
Group 1 is a valid selector letter, group 2 anything else in its place."
  (let ((case-fold-search t))
    (re-search-forward
     (concat "(\\s-*\\(?:CAM\\s-+\\(?:\\([ZUDAPR]\\)\\|\\([A-Za-z@][A-Za-z0-9@]*\\)\\)"
             "\\|ULT\\s-+\\(?:\\([ABCD]\\)\\|\\([A-Za-z@][A-Za-z0-9@]*\\)\\)\\)"
             "\\(?:[^A-Za-z0-9@]\\|$\\)")
     limit t)))

(defun rl1--operand-before-p (position)
  "Whether an operand ends just before POSITION, spaces aside.
As in the compiler's scanner, `-' before digits is then a minus (`B-5'), and
otherwise the sign of a constant (`A=-5', `(MOV -3,3)', `B--5' is B minus -5)."
  (save-excursion
    (save-match-data
      (goto-char position)
      (skip-chars-backward " \t")
      (and (looking-back "[A-Za-z0-9@)]" (1- (point)))
           ;; A call's name ends in a letter but is no operand: `(MOV -3,3)'.
           (not (looking-back "([ \t]*[A-Za-z@][A-Za-z0-9@]*" (line-beginning-position)))))))

(defun rl1--match-decimal (limit)
  "Find the next decimal constant before LIMIT, with its sign when it has one."
  (when (re-search-forward "-?[0-9]+" limit t)
    (let ((start (match-beginning 0)))
      (when (and (eq (char-after start) ?-) (rl1--operand-before-p start))
        (set-match-data (list (1+ start) (match-end 0)))))
    t))

(defconst rl1-font-lock-keywords
  '(;; Labels start a line; :96-:99 receive the jumps of a lost guidance line.
    ("^[ \t]*\\(:[0-9][0-9]\\)\\(?:[^0-9]\\|$\\)" 1 font-lock-function-name-face)
    (":[0-9]*" . font-lock-warning-face)
    ;; ?V=#NN, ?V>#NN, ?V<#NN
    ("\\(\\?\\)[ \t]*\\(?:\\([s-z]\\)\\|\\([A-Za-z@]\\)\\)[ \t]*\\([=<>]\\)"
     (1 font-lock-keyword-face) (2 'rl1-reserved-variable-face nil t)
     (3 font-lock-variable-name-face nil t) (4 'rl1-operator-face))
    ("\\?" . font-lock-keyword-face)
    ("\\(#[0-9][0-9]\\)\\(?:[^0-9]\\|$\\)" 1 font-lock-keyword-face)
    ("#[0-9]*" . font-lock-warning-face)
    (rl1--match-selector (1 font-lock-constant-face nil t) (2 font-lock-warning-face nil t)
                         (3 font-lock-constant-face nil t) (4 font-lock-warning-face nil t))
    (rl1--match-known-call 1 font-lock-builtin-face)
    ("(\\s-*\\([A-Za-z@][A-Za-z0-9@]*\\)" 1 font-lock-warning-face)
    ("\\$0*[0-9A-Fa-f]\\{1,4\\}\\_>" . font-lock-constant-face)
    ("\\$[0-9A-Za-z]*" . font-lock-warning-face)
    ("\\<[A-Za-z@][A-Za-z0-9@]+\\>" . font-lock-warning-face)
    ("\\(\\+\\+\\|--\\)\\(?:[^0-9]\\|$\\)" 1 'rl1-operator-face)
    (rl1--match-decimal . font-lock-constant-face)
    ("\\<[s-z]\\>" . 'rl1-reserved-variable-face)
    ("\\<[A-Za-z@]\\>" . font-lock-variable-name-face)
    ("[-+&|^<>=]" . 'rl1-operator-face)
    ("[;,]" . 'rl1-separator-face)
    ;; RL/I code is ASCII; other text belongs in a comment.
    ("[^[:ascii:]]+" . font-lock-warning-face))
  "Highlighting for `rl1-mode'; the first rule to claim a character wins.")

;;;###autoload
(define-derived-mode rl1-mode prog-mode "RL/I"
  "Major mode for RL/I robot programs."
  :syntax-table rl1-mode-syntax-table
  (setq-local comment-start "' ")
  (setq-local comment-end "")
  (setq-local comment-start-skip "'+[ \t]*")
  (setq-local font-lock-defaults '(rl1-font-lock-keywords)))

;;;###autoload
(add-to-list 'auto-mode-alist '("\\.[Rr][Oo][Bb]\\'" . rl1-mode))

;; The language server: `M-x eglot' in a .rob buffer starts rl1-lsp.
(with-eval-after-load 'eglot
  (defvar eglot-server-programs)
  (add-to-list 'eglot-server-programs '(rl1-mode . ("rl1-lsp"))))

(provide 'rl1-mode)

;;; rl1-mode.el ends here
