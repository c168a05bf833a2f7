-- The TADSL language client for Neovim: starts `tadslc lsp` for TAD buffers (and, with
-- `yaml = true`, YAML scenario answers), one client per root directory.
--
--   require('tadsl').setup({
--     cmd = { 'tadslc', 'lsp' },                       -- the server
--     settings = { tadsl = { profile = 'auto' } },     -- as `tadslc check --profile/--region/--non-scenario`
--     yaml = false,                                    -- also YAML answers
--     root_markers = { '.git', 'Cargo.toml' },
--   })
--
-- Works on Neovim 0.7 (vim.lsp.start_client and buf_attach_client) and on 0.8 and later
-- (vim.lsp.start, which reuses a client for the same root by itself).

local M = {}

local defaults = {
  cmd = { 'tadslc', 'lsp' },
  settings = { tadsl = { profile = 'auto' } },
  yaml = false,
  root_markers = { '.git', 'Cargo.toml' },
  on_attach = nil,
}

local clients = {} -- root directory -> client id (Neovim 0.7)

local function root_of(path, markers)
  local dir = vim.fn.fnamemodify(path, ':p:h')
  for _, marker in ipairs(markers) do
    local found = vim.fn.finddir(marker, dir .. ';')
    if found == '' then
      found = vim.fn.findfile(marker, dir .. ';')
    end
    if found ~= '' then
      return vim.fn.fnamemodify(found, ':p:h:h')
    end
  end
  return dir
end

local function config_for(opts, root)
  local settings = opts.settings
  return {
    name = 'tadsl',
    cmd = opts.cmd,
    root_dir = root,
    init_options = settings,
    settings = settings,
    on_attach = opts.on_attach,
    handlers = {
      -- the server pulls section `tadsl`; answer from the settings given here
      ['workspace/configuration'] = function(_, params)
        local out = {}
        for i, item in ipairs(params.items or {}) do
          out[i] = (item.section and settings[item.section]) or settings
        end
        return out
      end,
    },
  }
end

local function attach(opts, buf)
  local name = vim.api.nvim_buf_get_name(buf)
  if name == '' then
    return
  end
  local root = root_of(name, opts.root_markers)
  local config = config_for(opts, root)
  if vim.lsp.start then
    vim.lsp.start(config, { bufnr = buf })
    return
  end
  local id = clients[root]
  if not id or not vim.lsp.get_client_by_id(id) then
    id = vim.lsp.start_client(config)
    clients[root] = id
  end
  if id then
    vim.lsp.buf_attach_client(buf, id)
  end
end

function M.setup(user)
  local opts = vim.tbl_deep_extend('force', defaults, user or {})
  if vim.filetype and vim.filetype.add then
    vim.filetype.add({ extension = { tad = 'tad' } })
  end
  vim.cmd([[
    augroup tadsl_filetype
      autocmd!
      autocmd BufRead,BufNewFile *.tad setfiletype tad
    augroup END
  ]])
  local group = vim.api.nvim_create_augroup('tadsl', { clear = true })
  local patterns = { 'tad' }
  if opts.yaml then
    table.insert(patterns, 'yaml')
  end
  vim.api.nvim_create_autocmd('FileType', {
    group = group,
    pattern = patterns,
    callback = function(args)
      attach(opts, args.buf)
    end,
  })
  -- buffers already open
  for _, buf in ipairs(vim.api.nvim_list_bufs()) do
    if vim.api.nvim_buf_is_loaded(buf) and vim.tbl_contains(patterns, vim.bo[buf].filetype) then
      attach(opts, buf)
    end
  end
end

return M
