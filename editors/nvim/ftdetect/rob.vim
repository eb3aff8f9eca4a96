" .rob files are RL/I robot programs. Vim script, so that every Neovim version reads it
" (and Vim too).
autocmd BufNewFile,BufRead *.rob,*.ROB setfiletype rl1
