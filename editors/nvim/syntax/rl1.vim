" RL/I robot programs (.rob): highlighting without the language server, in Neovim and
" Vim. The classes are those of the VS Code grammar (editors/vscode/syntaxes/); where
" several rules match at one column, the last one defined wins.

if exists('b:current_syntax')
  finish
endif

" The built-in functions of RL/I (the paper's Tables 1-3).
let s:builtins = 'END FRE HLD ORG MVI MOV STR STL STX ROT TRC TIM KYC KYO SCN IMG CAM ULT LMP INP OUT FZO FZI'

" A word of RL/I is letters, digits and @ (a variable).
syntax iskeyword @,48-57,@-@
syntax case match

" What the compiler rejects: other text belongs in a comment, and a word of two or more
" characters is only a call's name.
syntax match rl1Error /[^\x00-\x7f]\+/
syntax match rl1Error /\<\k\k\+\>/

syntax match rl1Variable /\<[A-Za-z@]\>/
syntax match rl1Reserved /\<[s-z]\>/
syntax match rl1Number /\<\d\+\>/
syntax match rl1Error /\$\k*/
syntax match rl1Number /\$0*\x\{1,4}\>/
syntax match rl1Operator /[-+&|^<>=]/
syntax match rl1Delimiter /[;,]/

" Jumps: #NN, and ?V=#NN, ?V<#NN, ?V>#NN.
syntax match rl1Conditional /?/
syntax match rl1Error /#\d*/
syntax match rl1Jump /#\d\d\d\@!/

" Labels start a line; :96-:99 receive the jumps of a lost guidance line.
syntax match rl1Error /:\d*/
syntax match rl1Label /^\s*\zs:\d\d\d\@!/
syntax match rl1Handler /^\s*\zs:9[6-9]\d\@!/

" Calls: a name after ( is a built-in, in any letter case; CAM and ULT take a selector.
syntax match rl1Error /(\s*\zs\k\+/
execute 'syntax match rl1Builtin /\c(\s*\zs\%(' . join(split(s:builtins), '\|') . '\)\k\@!/'
" The call's name is matched first, so a selector looks behind to it.
syntax match rl1Error /\c\%((\s*\%(CAM\|ULT\)\s\+\)\@<=\k\+/
syntax match rl1Selector /\c\%((\s*CAM\s\+\)\@<=[ZUDAPR]\k\@!/
syntax match rl1Selector /\c\%((\s*ULT\s\+\)\@<=[ABCD]\k\@!/

syntax match rl1Comment /'.*$/

highlight default link rl1Comment Comment
highlight default link rl1Label Label
highlight default link rl1Handler Exception
highlight default link rl1Jump Keyword
highlight default link rl1Conditional Conditional
highlight default link rl1Builtin Function
highlight default link rl1Selector Constant
highlight default link rl1Variable Identifier
highlight default link rl1Reserved Special
highlight default link rl1Number Number
highlight default link rl1Operator Operator
highlight default link rl1Delimiter Delimiter
highlight default link rl1Error Error

let b:current_syntax = 'rl1'
