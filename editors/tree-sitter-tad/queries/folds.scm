; Folds: every braced body, lists and text blocks.

[
  (scenario)
  (block)
  (list)
  (text_block)
] @fold
