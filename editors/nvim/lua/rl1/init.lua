-- Starts the rl1-lsp language server for RL/I buffers with Neovim's own LSP client:
-- diagnostics, hover, completion and (semantic-token) highlighting come from it.
local M = {}

M.defaults = {
  cmd = { 'rl1-lsp' },
  -- The folder that holds one of these is the workspace root: the project file of
  -- `rl1c check` first (the server reads it from there), then the usual ones.
  root_markers = { 'rl1.toml', 'pyproject.toml', '.git' },
}

local function root_dir(markers, buffer)
  local found = vim.fs.find(markers, {
    upward = true,
    path = vim.fs.dirname(vim.api.nvim_buf_get_name(buffer)),
  })[1]
  return found and vim.fs.dirname(found) or vim.fn.getcwd()
end

--- Register the server for the `rl1` filetype. Options override M.defaults, e.g.
--- require('rl1').setup({ cmd = { '/path/to/rl1/.venv/bin/rl1-lsp' } })
function M.setup(opts)
  local config = vim.tbl_deep_extend('force', M.defaults, opts or {})
  if vim.fn.has('nvim-0.8') == 0 then
    vim.notify(
      'rl1: the language server needs Neovim 0.8 or newer; until then, highlighting works '
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
  vim.api.nvim_create_autocmd('FileType', {
    group = vim.api.nvim_create_augroup('rl1_lsp', { clear = true }),
    pattern = 'rl1',
    callback = function(event)
      vim.lsp.start(
        { name = 'rl1', cmd = config.cmd, root_dir = root_dir(config.root_markers, event.buf) },
        { bufnr = event.buf }
      )
    end,
  })
end

return M
