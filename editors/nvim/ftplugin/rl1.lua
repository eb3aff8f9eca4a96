-- In RL/I a comment runs from ' to the end of the line (gc uses commentstring).
vim.bo.commentstring = "' %s"
vim.bo.comments = ":'"
vim.b.undo_ftplugin = 'setlocal commentstring< comments<'
