-- tests/editors/test_neovim.py starts Neovim headless with an init file and a .rob file
-- to edit, then runs this: it waits, polling, for the diagnostics of that buffer (the
-- language server's, once rl1-lsp has checked it), writes them as JSON to the file named
-- by RL1_DIAGNOSTICS_OUT, and ends Neovim. If none come within RL1_DIAGNOSTICS_SECONDS, it
-- writes what Neovim said instead, so that the test's failure shows why.
local buffer = vim.api.nvim_get_current_buf()
local seconds = tonumber(os.getenv('RL1_DIAGNOSTICS_SECONDS') or '30')
vim.wait(seconds * 1000, function()
  return #vim.diagnostic.get(buffer) > 0
end, 50)

local shown = {}
for _, diagnostic in ipairs(vim.diagnostic.get(buffer)) do
  -- Before 0.8 the server's code is only in user_data.
  local lsp = diagnostic.user_data and diagnostic.user_data.lsp or {}
  table.insert(shown, {
    line = diagnostic.lnum + 1,
    column = diagnostic.col + 1,
    source = diagnostic.source or vim.NIL,
    code = diagnostic.code or lsp.code or vim.NIL,
    message = diagnostic.message,
  })
end
local clients = {}
for _, client in pairs(vim.lsp.buf_get_clients(buffer)) do
  table.insert(clients, { name = client.name, root = client.config.root_dir })
end
local out = assert(io.open(os.getenv('RL1_DIAGNOSTICS_OUT'), 'w'))
out:write(vim.fn.json_encode({
  filetype = vim.bo[buffer].filetype,
  clients = clients,
  diagnostics = shown,
  messages = vim.api.nvim_exec('messages', true),
}))
out:close()
vim.cmd('qall!')
