;;; flymake_diagnostics.el --- write out what flymake shows of a file  -*- lexical-binding: t; -*-

;; tests/editors/test_emacs.py starts Emacs as a user does, on a terminal, with an init
;; file and a .rob file to visit, and loads this after both: it waits, polling, for
;; flymake's diagnostics in that file's buffer (eglot's, once rl1-lsp has checked it),
;; writes them as JSON to the file named by RL1_DIAGNOSTICS_OUT, and ends Emacs.  If
;; none come within RL1_DIAGNOSTICS_SECONDS, it writes what Emacs said instead, so
;; that the test's failure shows why.

;;; Code:

(require 'json)
(require 'flymake)
(require 'seq)

(defvar rl1-diagnostics--deadline
  (+ (float-time) (string-to-number (or (getenv "RL1_DIAGNOSTICS_SECONDS") "30"))))

(defun rl1-diagnostics--buffer ()
  "The buffer of the one .rob file Emacs was asked to visit."
  (seq-find (lambda (buffer) (string-match-p "\\.rob\\'" (or (buffer-file-name buffer) "")))
            (buffer-list)))

(defun rl1-diagnostics--of (buffer)
  "Each flymake diagnostic of BUFFER as an alist: line and column from 1, text."
  (with-current-buffer buffer
    (mapcar (lambda (diagnostic)
              (save-excursion
                (goto-char (flymake-diagnostic-beg diagnostic))
                `((line . ,(line-number-at-pos))
                  (column . ,(1+ (current-column)))
                  (text . ,(flymake-diagnostic-text diagnostic)))))
            (flymake-diagnostics))))

(defun rl1-diagnostics--finish (diagnostics)
  (let ((mode (let ((buffer (rl1-diagnostics--buffer)))
                (and buffer (buffer-local-value 'major-mode buffer)))))
    (with-temp-file (getenv "RL1_DIAGNOSTICS_OUT")
      (insert (json-encode
               `((mode . ,(symbol-name mode))
                 (diagnostics . ,(vconcat diagnostics))
                 (messages . ,(with-current-buffer (messages-buffer) (buffer-string))))))))
  (kill-emacs 0))

(defun rl1-diagnostics--poll ()
  (let* ((buffer (rl1-diagnostics--buffer))
         (diagnostics (and buffer (rl1-diagnostics--of buffer))))
    (when (or diagnostics (> (float-time) rl1-diagnostics--deadline))
      (rl1-diagnostics--finish diagnostics))))

(run-with-timer 0.05 0.05 #'rl1-diagnostics--poll)

;;; flymake_diagnostics.el ends here
