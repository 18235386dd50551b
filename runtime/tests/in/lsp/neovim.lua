-- Neovim's own LSP client driving `sdfc lsp` (runtime/tests/lsp.rs runs this with
-- `nvim --headless --clean`): open main.sdf, which has a mistake, wait for its diagnostic,
-- apply the quick fix through Neovim's workspace edit, hover a shape, go to the definition of
-- a function of the imported lib.sdf. What Neovim saw is written as JSON to $SDFC_OUT; the
-- Rust test compares it with what it expects. Written for Neovim 0.7 (Debian 12) and later.

local bin, dir, out = os.getenv("SDFC_BIN"), os.getenv("SDFC_DIR"), os.getenv("SDFC_OUT")
local seen = { steps = {} }
local TIMEOUT = 20000

local function step(name)
  table.insert(seen.steps, name)
end

local function position(line, character)
  return {
    textDocument = { uri = vim.uri_from_bufnr(0) },
    position = { line = line, character = character },
  }
end

-- The first result of a request to the server, waiting for it.
local function ask(method, params)
  local answers = vim.lsp.buf_request_sync(0, method, params, TIMEOUT)
  for _, a in pairs(answers or {}) do
    if a.error then
      error(method .. ": " .. vim.inspect(a.error))
    end
    return a.result
  end
  error(method .. ": no answer")
end

local function main()
  vim.cmd("edit " .. vim.fn.fnameescape(dir .. "/main.sdf"))
  vim.bo.filetype = "sdf"
  local buf = vim.api.nvim_get_current_buf()
  local config = { name = "sdfc", cmd = { bin, "lsp" }, root_dir = dir }
  if vim.lsp.start then
    vim.lsp.start(config)
  else
    vim.lsp.buf_attach_client(buf, vim.lsp.start_client(config))
  end
  step("started")

  -- The mistake's diagnostic, published after the server's debounce.
  local function errors()
    return vim.diagnostic.get(buf, { severity = vim.diagnostic.severity.ERROR })
  end
  assert(vim.wait(TIMEOUT, function() return #errors() > 0 end, 20), "no error published")
  local d = errors()[1]
  seen.diagnostic = {
    lnum = d.lnum, col = d.col, end_lnum = d.end_lnum, end_col = d.end_col,
    message = d.message, code = d.code,
  }
  step("diagnostic")

  -- Its quick fix, as `gra` (or `:lua vim.lsp.buf.code_action()`) offers it at the cursor:
  -- the menu answered with its first entry, the edit applied by Neovim, which sends the
  -- change to the server.
  vim.api.nvim_win_set_cursor(0, { d.lnum + 1, d.col })
  local original = vim.api.nvim_buf_get_lines(buf, d.lnum, d.lnum + 1, false)[1]
  vim.ui.select = function(items, opts, on_choice)
    local first = items[1]
    seen.fix = first and (first.title or (first[2] and first[2].title) or (first.action and first.action.title))
    on_choice(first, 1)
  end
  vim.lsp.buf.code_action()
  assert(vim.wait(TIMEOUT, function()
    return vim.api.nvim_buf_get_lines(buf, d.lnum, d.lnum + 1, false)[1] ~= original
  end, 20), "the quick fix was not applied")
  seen.fixed_line = vim.api.nvim_buf_get_lines(buf, d.lnum, d.lnum + 1, false)[1]
  assert(vim.wait(TIMEOUT, function() return #errors() == 0 end, 20), "the fix left errors")
  step("fixed")

  -- A hover on the shape the fix named.
  local line = seen.fixed_line
  local col = assert(line:find("sphere", 1, true)) - 1
  local hover = ask("textDocument/hover", position(d.lnum, col + 2))
  seen.hover = hover and hover.contents and hover.contents.value
  step("hover")

  -- Go to the definition of the imported function, as `gd` would: Neovim opens lib.sdf.
  local lines = vim.api.nvim_buf_get_lines(buf, 0, -1, false)
  for i, l in ipairs(lines) do
    local c = l:find("post(", 1, true)
    if c then
      vim.api.nvim_win_set_cursor(0, { i, c })
      break
    end
  end
  vim.lsp.buf.definition()
  assert(vim.wait(TIMEOUT, function()
    return vim.api.nvim_buf_get_name(0):match("lib%.sdf$") ~= nil
  end, 20), "definition did not open lib.sdf")
  local cursor = vim.api.nvim_win_get_cursor(0)
  seen.definition = { file = vim.fn.fnamemodify(vim.api.nvim_buf_get_name(0), ":t"), row = cursor[1], col = cursor[2] }
  step("definition")
end

local ok, err = pcall(main)
seen.ok = ok
seen.error = ok and vim.NIL or tostring(err)
local f = assert(io.open(out, "w"))
f:write(vim.fn.json_encode(seen))
f:close()
vim.cmd("qa!")
