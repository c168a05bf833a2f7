-- TAD buffers: `//` comments and two-space indentation, as `tadslc fmt` writes them.
vim.bo.commentstring = '// %s'
vim.bo.comments = '://'
vim.bo.expandtab = true
vim.bo.shiftwidth = 2
vim.bo.softtabstop = 2
vim.bo.tabstop = 2
