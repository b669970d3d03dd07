-- btc for Neovim (>= 0.8): the `btrules` filetype and the btc language
-- server (`btc lsp`, over stdio) for `.btrules` files, and for `.pddl` files
-- so that the domains and problems you open get their diagnostics too.
--
-- Needs `btc` on PATH (from the btc repository: `cargo install --path .`).
-- Put this file in your config, e.g. as ~/.config/nvim/plugin/btc.lua, or
-- paste one of the variants below into your init.lua.
--
-- Highlighting comes from the server's semantic tokens (Neovim >= 0.9
-- shows them by itself); there is no Vim syntax file for .btrules.

-- Variant 1: plain Neovim, no plugin -------------------------------------

-- Recognise the files. PDDL has no filetype in Neovim's own list.
vim.filetype.add({
  extension = {
    btrules = 'btrules',
    pddl = 'pddl',
  },
})

local group = vim.api.nvim_create_augroup('btc', { clear = true })

vim.api.nvim_create_autocmd('FileType', {
  group = group,
  pattern = { 'btrules', 'pddl' },
  callback = function(args)
    if vim.bo[args.buf].filetype == 'btrules' then
      -- `gc` (Neovim >= 0.10, or a comment plugin) and formatoptions use it.
      vim.bo[args.buf].commentstring = '// %s'
    else
      vim.bo[args.buf].commentstring = '; %s'
    end
    local file = vim.api.nvim_buf_get_name(args.buf)
    -- The project root: the nearest enclosing directory with a `.git`,
    -- else the file's own directory. vim.lsp.start reuses one server for
    -- every buffer with the same name and root_dir.
    local git = vim.fs.find({ '.git' }, { upward = true, path = vim.fs.dirname(file) })[1]
    vim.lsp.start({
      name = 'btc',
      cmd = { 'btc', 'lsp' },
      root_dir = vim.fs.dirname(git or file),
    }, { bufnr = args.buf })
  end,
})

-- Once the server is attached, Neovim (0.8) sets omnifunc (completion with
-- <C-x><C-o>), tagfunc (<C-]> goes to the definition) and formatexpr (gq).
-- Neovim 0.10 maps K to hover; 0.11 adds grn (rename), gra (code action),
-- grr (references). Otherwise call vim.lsp.buf.hover(), .definition(),
-- .references(), .rename(), .code_action(), .format() (the `btc fmt` layout)
-- and vim.diagnostic.open_float() from mappings of your own.

-- Variant 2: nvim-lspconfig ------------------------------------------------
--
-- With nvim-lspconfig, use this instead of the autocmd above (keep the
-- vim.filetype.add call): lspconfig has no `btc` of its own, so declare it
-- through `lspconfig.configs`, then set it up like any other server.
--
--   local lspconfig = require('lspconfig')
--   local configs = require('lspconfig.configs')
--   if not configs.btc then
--     configs.btc = {
--       default_config = {
--         cmd = { 'btc', 'lsp' },
--         filetypes = { 'btrules', 'pddl' },
--         root_dir = lspconfig.util.root_pattern('.git'),
--         single_file_support = true,
--       },
--       docs = {
--         description = 'btc: the .btrules language server (`btc lsp`)',
--       },
--     }
--   end
--   lspconfig.btc.setup({})
--
-- Variant 3: Neovim >= 0.11, with no plugin, the same in its own API:
--
--   vim.lsp.config('btc', {
--     cmd = { 'btc', 'lsp' },
--     filetypes = { 'btrules', 'pddl' },
--     root_markers = { '.git' },
--   })
--   vim.lsp.enable('btc')
