;;; rl1-mode-tests.el --- ERT tests for rl1-mode  -*- lexical-binding: t; -*-

;; Run: emacs -batch -L . -l rl1-mode-tests.el -f ert-run-tests-batch-and-exit

;;; Code:

(require 'ert)
(require 'rl1-mode)

(defun rl1-tests--face-at (line text &optional nth)
  "The face of the NTH (from 1) occurrence of TEXT in LINE, highlighted by `rl1-mode'."
  (with-temp-buffer
    (insert line "\n")
    (rl1-mode)
    (font-lock-ensure)
    (goto-char (point-min))
    (dotimes (_ (or nth 1))
      (search-forward text))
    (get-text-property (match-beginning 0) 'face)))

(ert-deftest rl1-mode-minus-after-an-operand-is-an-operator ()
  (should (eq (rl1-tests--face-at "A=B--5" "-") 'rl1-operator-face))
  (should (eq (rl1-tests--face-at "A=B--5" "-5") 'font-lock-constant-face))
  (should (eq (rl1-tests--face-at "A=B-5" "-") 'rl1-operator-face))
  (should (eq (rl1-tests--face-at "A=-5" "-") 'font-lock-constant-face))
  (should (eq (rl1-tests--face-at "(MOV -3,-3)" "-3") 'font-lock-constant-face)))

(ert-deftest rl1-mode-decrement-is-an-operator ()
  (should (eq (rl1-tests--face-at "C--" "--") 'rl1-operator-face)))

(ert-deftest rl1-mode-calls-and-selectors ()
  (should (eq (rl1-tests--face-at "(CAM A 90)" "CAM") 'font-lock-builtin-face))
  (should (eq (rl1-tests--face-at "(CAM A 90)" "A" 2) 'font-lock-constant-face))
  (should (eq (rl1-tests--face-at "(ULT A)" "A") 'font-lock-constant-face))
  (should (eq (rl1-tests--face-at "(ULT E)" "E") 'font-lock-warning-face))
  (should (eq (rl1-tests--face-at "(mov 1,1)" "mov") 'font-lock-builtin-face))
  (should (eq (rl1-tests--face-at "(FOO 1)" "FOO") 'font-lock-warning-face)))

(ert-deftest rl1-mode-labels-and-jumps ()
  (should (eq (rl1-tests--face-at ":10 A=1" ":10") 'font-lock-function-name-face))
  (should (eq (rl1-tests--face-at ":5" ":5") 'font-lock-warning-face))
  (should (eq (rl1-tests--face-at "A=1 :10" ":10") 'font-lock-warning-face))
  (should (eq (rl1-tests--face-at "?A>#12" "?") 'font-lock-keyword-face))
  (should (eq (rl1-tests--face-at "?A>#12" ">") 'rl1-operator-face))
  (should (eq (rl1-tests--face-at "?A>#12" "#12") 'font-lock-keyword-face))
  (should (eq (rl1-tests--face-at "#5" "#5") 'font-lock-warning-face)))

(ert-deftest rl1-mode-variables-and-constants ()
  (should (eq (rl1-tests--face-at "L=x" "x") 'rl1-reserved-variable-face))
  (should (eq (rl1-tests--face-at "L=x" "L") 'font-lock-variable-name-face))
  (should (eq (rl1-tests--face-at "@--" "@") 'font-lock-variable-name-face))
  (should (eq (rl1-tests--face-at "H=$AA55" "$AA55") 'font-lock-constant-face))
  (should (eq (rl1-tests--face-at "H=$12345" "$12345") 'font-lock-warning-face))
  (should (eq (rl1-tests--face-at "AB=5" "AB") 'font-lock-warning-face)))

(ert-deftest rl1-mode-comments-in-any-script ()
  (should (eq (rl1-tests--face-at "(FRE) ' 停止 (MOV 3,3)" "停止") 'font-lock-comment-face))
  (should (eq (rl1-tests--face-at "(FRE) ' 停止 (MOV 3,3)" "MOV") 'font-lock-comment-face))
  (should (eq (rl1-tests--face-at "A=１" "１") 'font-lock-warning-face)))

(ert-deftest rl1-mode-registers-rob-files-and-the-server ()
  (should (eq (assoc-default "SAMPLE.ROB" auto-mode-alist #'string-match) 'rl1-mode))
  ;; Before Emacs 29 eglot may be missing: a stand-in still runs the set-up.
  (unless (require 'eglot nil t)
    (defvar eglot-server-programs nil)
    (provide 'eglot))
  (should (equal (alist-get 'rl1-mode eglot-server-programs) '("rl1-lsp"))))

;;; rl1-mode-tests.el ends here
