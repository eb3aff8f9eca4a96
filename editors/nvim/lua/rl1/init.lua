-- Starts the rl1-lsp language server for RL/I buffers with Neovim's own LSP client:
-- diagnostics, hover, completion and (semantic-token) highlighting come from it.
local M = {}

M.defaults = {
  cmd = { 'rl1-lsp' },
  -- The folder that holds one of these is the workspace root: the project file of
  -- `rl1c check` first (the server reads it from there), then the usual ones.
  root_markers = { 'rl1.toml', 'pyproject.toml', '.git' },
}

-- The nearest folder, from the buffer's file's up, that holds one of the markers, else the
-- working directory. (vim.fs.find, which would do, comes with 0.8.)
local function root_dir(markers, buffer)
  local folder = vim.fn.fnamemodify(vim.api.nvim_buf_get_name(buffer), ':p:h')
  while true do
    for _, marker in ipairs(markers) do
      if vim.loop.fs_stat(folder .. '/' .. marker) then
        return folder
      end
    end
    local parent = vim.fn.fnamemodify(folder, ':h')
    if parent == folder then
      return vim.fn.getcwd()
    end
    folder = parent
  end
end

--- Register the server for the `rl1` filetype. Options override M.defaults, e.g.
--- require('rl1').setup({ cmd = { '/path/to/rl1/.venv/bin/rl1-lsp' } })
function M.setup(opts)
  local config = vim.tbl_deep_extend('force', M.defaults, opts or {})
  if vim.fn.has('nvim-0.7') == 0 then
    vim.notify(
      'rl1: the language server needs Neovim 0.7 or newer; until then, highlighting works '
        .. 'and :compiler rl1c, then :make, checks the current file',
      vim.log.levels.WARN
    )
    return
  end
  if vim.fn.executable(config.cmd[1]) == 0 then
    vim.notify(
      ('rl1: %s was not found: install the rl1 Python package (pipx install /path/to/rl1) '
        .. "or pass its full path: require('rl1').setup({ cmd = { '/path/to/rl1-lsp' } })")
        :format(config.cmd[1]),
      vim.log.levels.WARN
    )
    return
  end
  if vim.fn.has('nvim-0.11') == 1 then
    vim.lsp.config('rl1', { cmd = config.cmd, filetypes = { 'rl1' }, root_markers = config.root_markers })
    vim.lsp.enable('rl1')
    return
  end
  -- Before 0.11, one client for each workspace root, attached to each of its buffers: what
  -- vim.lsp.start does from 0.8 on, written with what 0.7 has.
  local clients = {}
  vim.api.nvim_create_autocmd('FileType', {
    group = vim.api.nvim_create_augroup('rl1_lsp', { clear = true }),
    pattern = 'rl1',
    callback = function(event)
      local root = root_dir(config.root_markers, event.buf)
      local client = clients[root] and vim.lsp.get_client_by_id(clients[root])
      if not client or client.is_stopped() then
        clients[root] = vim.lsp.start_client({ name = 'rl1', cmd = config.cmd, root_dir = root })
      end
      if clients[root] then
        vim.lsp.buf_attach_client(event.buf, clients[root])
      end
    end,
  })
end

return M
