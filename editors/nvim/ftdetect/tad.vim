" TAD traffic scenarios (TADSL)
autocmd BufRead,BufNewFile *.tad setfiletype tad
