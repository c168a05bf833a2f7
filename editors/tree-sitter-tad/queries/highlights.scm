; TAD highlights. Capture names are the common ones (nvim-treesitter's, which the
; tree-sitter CLI also uses). Every name node is captured by exactly one pattern, so the
; result does not depend on whether an editor lets the first or the last match win.

; Keywords

["scenario" "actor"] @keyword

"use" @keyword.import

"of" @keyword.operator

(unspecified) @constant.builtin

; Items and members

(path (identifier) @module)

(declaration kind: (identifier) @type)

(declaration name: (identifier) @constant)

(scenario name: (identifier) @function)

(section name: (identifier) @module)

(actor name: (identifier) @variable)

(actor type: (words (identifier) @type))

(key) @property

; Values: names are vocabulary symbols, except a position's reference (ego, an actor
; group, a road element)

(field value: (words (identifier) @constant))

(choice (words (identifier) @constant))

(list (words (identifier) @constant))

(position relation: (words (identifier) @constant))

(position reference: (words (identifier) @variable))

(number) @number

(unit) @type.builtin

(string) @string

(escape_sequence) @string.escape

(text_block) @string

(comment) @comment

; Punctuation

["{" "}" "[" "]"] @punctuation.bracket

["," ":" "."] @punctuation.delimiter

[".." "|"] @operator
