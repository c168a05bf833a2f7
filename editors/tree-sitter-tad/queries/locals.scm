; Scopes: an actor group's name is defined in its scenario and referenced by the
; positions of other groups (`position: behind of herd`).

(scenario) @local.scope

(actor name: (identifier) @local.definition)

(position reference: (words (identifier) @local.reference))
