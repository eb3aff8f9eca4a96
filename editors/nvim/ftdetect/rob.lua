-- .rob files are RL/I robot programs.
vim.filetype.add({ extension = { rob = 'rl1', ROB = 'rl1' } })
