" `:compiler rl1c`, then `:make`: rl1c checks the current file and its concise lines,
" FILE:LINE:COL: SEVERITY[CODE]: MESSAGE, fill the quickfix list. Diagnostics without
" the language server (Neovim 0.7, or Vim).
if exists('current_compiler')
  finish
endif
let current_compiler = 'rl1c'

CompilerSet makeprg=rl1c\ check\ --format\ concise\ %:S
" %t takes the severity's first letter (e, w or i); the text keeps the code. Every other
" line (the summary, `1 file checked: ...`) is left out of the list (%-G).
CompilerSet errorformat=%f:%l:%c:\ %t%*[a-z]%m,%-G%.%#
