/**
 * @file TAD, the traffic-scenario language of TADSL: a grammar for highlighting and structure.
 * @license Apache-2.0
 *
 * The compiler's lalrpop grammar (compiler/syntax/src/grammar.lalrpop) is the source of
 * truth; this follows its normative EBNF (spec/language.md §3) and its lexer
 * (compiler/syntax/src/lexer.rs: keywords, units, keys, strings). Like the compiler's
 * concrete syntax tree it is generic: sections, fields and declaration kinds are names,
 * which the schema checks later, so a misspelt field is still a field here.
 *
 * A field key is a name with its `:` on the same line (`speed: 38 km/h lane: 2` is two
 * fields). src/scanner.c recognises the name of a key by looking ahead for the colon, so
 * the tree keeps the name and the `:` apart while values need no separators.
 */

const commaSep = (rule) => optional(seq(rule, repeat(seq(',', rule)), optional(',')));

module.exports = grammar({
  name: 'tad',

  externals: ($) => [$.key],

  // Whitespace as in spec §1 (a leading byte-order mark included), and `//` comments.
  extras: ($) => [/[ \t\r\n\f\uFEFF]/, $.comment],

  word: ($) => $.identifier,

  rules: {
    source_file: ($) => repeat($._item),

    _item: ($) => choice($.use, $.scenario, $.declaration),

    // `use a.b`
    use: ($) => seq('use', field('path', $.path)),

    path: ($) => seq($.identifier, repeat(seq('.', $.identifier))),

    // `KIND NAME` or `KIND NAME { FIELD* }`, e.g. `weather clear { aliases: [sunny] }`
    declaration: ($) =>
      seq(
        field('kind', $.identifier),
        field('name', $.identifier),
        optional(field('body', $.block)),
      ),

    // `scenario NAME { MEMBER* }`
    scenario: ($) =>
      seq(
        'scenario',
        field('name', $.identifier),
        '{',
        repeat(choice($.section, $.actor)),
        '}',
      ),

    // `road { FIELD* }`
    section: ($) => seq(field('name', $.identifier), field('body', $.block)),

    // `actor NAME: [COUNT] TYPE { FIELD* }`
    actor: ($) =>
      seq(
        'actor',
        field('name', alias($.key, $.identifier)),
        ':',
        optional(field('count', choice($.number, alias($._count_range, $.range), $.unspecified))),
        field('type', choice($.words, $.unspecified)),
        field('body', $.block),
      ),

    _count_range: ($) => seq(field('low', $.number), '..', field('high', $.number)),

    block: ($) => seq('{', repeat($.field), '}'),

    field: ($) => seq(field('key', $.key), ':', field('value', $._value)),

    _value: ($) =>
      choice(
        $.unspecified,
        $.number,
        $.quantity,
        $.range,
        $.choice,
        $.string,
        $.text_block,
        $.words,
        $.position,
        $.list,
      ),

    // `38 km/h`
    quantity: ($) => seq($.number, $.unit),

    // `30..40 km/h`, `30 km/h..40 km/h`, `3..5`
    range: ($) =>
      seq(
        field('low', choice($.number, $.quantity)),
        '..',
        field('high', choice($.number, $.quantity)),
      ),

    // `clear | cloudy`
    choice: ($) => seq($.words, repeat1(seq('|', $.words))),

    // `left_front of ego`
    position: ($) => seq(field('relation', $.words), 'of', field('reference', $.words)),

    list: ($) => seq('[', commaSep($._value), ']'),

    // One name in a valid file; more are parsed so that the compiler can explain (E0207).
    words: ($) => repeat1($.identifier),

    unspecified: (_) => 'unspecified',

    number: (_) => /-?[0-9]+(\.[0-9]+)?/,

    unit: (_) => choice('km/h', 'mph', 'm/s', 'm', 's'),

    string: ($) =>
      seq(
        '"',
        repeat(choice(alias(token.immediate(prec(1, /[^"\\\n]+/)), $.string_content), $.escape_sequence)),
        token.immediate('"'),
      ),

    escape_sequence: (_) => token.immediate(seq('\\', choice(/["\\ntr]/, /u\{[0-9a-fA-F]{1,6}\}/))),

    // Ends at the first `"""`; no escapes.
    text_block: (_) => token(seq('"""', /([^"]|"[^"]|""[^"])*/, '"""')),

    identifier: (_) => /[A-Za-z_][A-Za-z0-9_]*/,

    comment: (_) => token(seq('//', /[^\n]*/)),
  },
});
