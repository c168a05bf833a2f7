-- End-to-end test of `tadslc lsp` with a real editor: headless Neovim (0.7.2 and later)
-- as the client, run by compiler/tadslc/tests/lsp_neovim.rs:
--   TADSLC=… TAD_CLEAN=example.tad TAD_BROKEN=broken.tad nvim --headless -u NONE -i NONE -c 'luafile e2e.lua'
-- Prints `ok <check>` per check and `PASS` at the end; any failure exits non-zero.

local tadslc = assert(os.getenv('TADSLC'), 'TADSLC')
local clean = assert(os.getenv('TAD_CLEAN'), 'TAD_CLEAN')
local broken = assert(os.getenv('TAD_BROKEN'), 'TAD_BROKEN')
local plugin = os.getenv('TAD_NVIM_PLUGIN')

local function say(line)
  io.stdout:write(line .. '\n')
  io.stdout:flush()
end

local function fail(message)
  io.stderr:write('FAIL ' .. message .. '\n')
  io.stderr:flush()
  vim.cmd('cquit! 1')
end

local function check(condition, message)
  if not condition then
    fail(message)
  end
end

local classes = {}
vim.lsp.handlers['tadsl/scenarioClass'] = function(_, result)
  classes[result.uri] = result.class
end

local client_id
local function attach(path)
  vim.cmd('edit ' .. vim.fn.fnameescape(path))
  local buf = vim.api.nvim_get_current_buf()
  vim.bo[buf].filetype = 'tad'
  if plugin then
    -- the editor package's own set-up attaches on the FileType event
    vim.wait(10000, function() return #vim.lsp.buf_get_clients(buf) > 0 end, 20)
    local clients = vim.lsp.buf_get_clients(buf)
    for id, _ in pairs(clients) do client_id = id end
  else
    if not client_id then
      client_id = vim.lsp.start_client({
        name = 'tadsl',
        cmd = { tadslc, 'lsp' },
        root_dir = vim.fn.fnamemodify(path, ':h'),
        init_options = { tadsl = { profile = 'auto' } },
      })
    end
    vim.lsp.buf_attach_client(buf, client_id)
  end
  check(client_id ~= nil, 'no client attached to ' .. path)
  local ok = vim.wait(10000, function()
    local c = vim.lsp.get_client_by_id(client_id)
    return c ~= nil and c.initialized
  end, 20)
  check(ok, 'the server did not initialise')
  return buf, vim.uri_from_bufnr(buf)
end

local function request(buf, method, params)
  local responses, err = vim.lsp.buf_request_sync(buf, method, params, 10000)
  check(responses ~= nil, method .. ' failed: ' .. tostring(err))
  for _, response in pairs(responses) do
    check(response.err == nil, method .. ' error: ' .. vim.inspect(response.err))
    return response.result
  end
  fail(method .. ': no response')
end

local function position_of(buf, pattern, after)
  local lines = vim.api.nvim_buf_get_lines(buf, 0, -1, false)
  for i, line in ipairs(lines) do
    local s = line:find(pattern, 1, true)
    if s then return { line = i - 1, character = s - 1 + (after or 0) } end
  end
  fail('no ' .. pattern .. ' in the buffer')
end

local function codes(buf)
  local out = {}
  for _, d in ipairs(vim.diagnostic.get(buf)) do
    out[#out + 1] = tostring(d.code or (d.user_data and d.user_data.lsp and d.user_data.lsp.code))
  end
  table.sort(out)
  return table.concat(out, ',')
end

-- 1. a clean example: published as complete, no diagnostics
local buf, uri = attach(clean)
check(vim.wait(10000, function() return classes[uri] ~= nil end, 20), 'no class for the example')
check(classes[uri] == 'complete', 'the example is ' .. tostring(classes[uri]))
check(#vim.diagnostic.get(buf) == 0, 'diagnostics on a clean example: ' .. codes(buf))
say('ok diagnostics-clean')

-- 2. hover on an actor type
local hover = request(buf, 'textDocument/hover', {
  textDocument = { uri = uri },
  position = position_of(buf, 'pedestrian {', 2),
})
check(hover and hover.contents, 'no hover')
local text = type(hover.contents) == 'table' and (hover.contents.value or vim.inspect(hover.contents)) or hover.contents
check(text:find('pedestrian', 1, true) ~= nil, 'hover does not name the type: ' .. text)
say('ok hover')

-- 3. completion: only behaviours a pedestrian can perform
local behavior = position_of(buf, 'behavior: cross', #'behavior: ')
vim.api.nvim_buf_set_text(buf, behavior.line, behavior.character, behavior.line, behavior.character + 5, { '' })
local result = request(buf, 'textDocument/completion', { textDocument = { uri = uri }, position = behavior })
local items = result and (result.items or result) or {}
local labels = {}
for _, item in ipairs(items) do labels[item.label] = true end
check(labels['cross'], 'completion lacks `cross`: ' .. vim.inspect(vim.tbl_keys(labels)))
check(not labels['turn_left'], 'completion offers `turn_left` to pedestrians')
vim.cmd('silent! undo')
say('ok completion')

-- 4. a broken file: diagnostics with codes
local bbuf, buri = attach(broken)
check(vim.wait(10000, function() return #vim.diagnostic.get(bbuf) > 0 end, 20), 'no diagnostics on the broken file')
local found = codes(bbuf)
check(found:find('W0401', 1, true) and found:find('E0400', 1, true), 'codes: ' .. found)
say('ok diagnostics-broken ' .. found)

-- 5. the quick fix for the alias, applied
local alias
for _, d in ipairs(vim.diagnostic.get(bbuf)) do
  if tostring(d.code) == 'W0401' then alias = d end
end
check(alias ~= nil, 'no W0401 diagnostic')
local range = {
  start = { line = alias.lnum, character = alias.col },
  ['end'] = { line = alias.end_lnum, character = alias.end_col },
}
local actions = request(bbuf, 'textDocument/codeAction', {
  textDocument = { uri = buri },
  range = range,
  context = { diagnostics = vim.lsp.diagnostic.get_line_diagnostics(bbuf, alias.lnum) },
})
local fix
for _, action in ipairs(actions or {}) do
  if action.kind == 'quickfix' and action.isPreferred then fix = action end
end
check(fix ~= nil, 'no preferred quick fix: ' .. vim.inspect(actions))
vim.lsp.util.apply_workspace_edit(fix.edit, 'utf-16')
local line = vim.api.nvim_buf_get_lines(bbuf, alias.lnum, alias.lnum + 1, false)[1]
check(line:find('weather: clear', 1, true) ~= nil, 'after the fix: ' .. line)
check(vim.wait(10000, function() return not codes(bbuf):find('W0401', 1, true) end, 20), 'W0401 stays after the fix')
say('ok quickfix')

-- 6. formatting applies the canonical layout
local before = table.concat(vim.api.nvim_buf_get_lines(bbuf, 0, -1, false), '\n')
local edits = request(bbuf, 'textDocument/formatting', {
  textDocument = { uri = buri },
  options = { tabSize = 2, insertSpaces = true },
})
check(edits ~= nil and #edits > 0, 'no formatting edits')
vim.lsp.util.apply_text_edits(edits, bbuf, 'utf-16')
local after = table.concat(vim.api.nvim_buf_get_lines(bbuf, 0, -1, false), '\n')
check(after ~= before, 'formatting changed nothing')
check(after:find('\n    time: daytime', 1, true) ~= nil, 'not canonical:\n' .. after)
say('ok formatting')

-- 7. stop the server cleanly
vim.lsp.stop_client(client_id)
check(vim.wait(5000, function() return vim.lsp.get_client_by_id(client_id) == nil end, 20), 'the server did not stop')
say('PASS')
vim.cmd('qa!')
