; Indentation (Helix style): the contents of braces and brackets are indented one level,
; and the closing bracket goes back.

[
  (scenario)
  (block)
  (list)
] @indent

[
  "}"
  "]"
] @outdent
