// The name of a field key (`speed` in `speed: 38 km/h`): a name followed by `:` on the
// same line, spaces and tabs allowed between them (spec §2.3). Tree-sitter's lexer cannot
// look past the end of a token, so this scanner reads the name, marks its end, and only
// then looks for the colon. Without a colon it declines and the name lexes as an
// identifier. It keeps no state.

#include "tree_sitter/parser.h"

enum TokenType { KEY };

void *tree_sitter_tad_external_scanner_create(void) { return NULL; }

void tree_sitter_tad_external_scanner_destroy(void *payload) { (void)payload; }

unsigned tree_sitter_tad_external_scanner_serialize(void *payload, char *buffer) {
  (void)payload;
  (void)buffer;
  return 0;
}

void tree_sitter_tad_external_scanner_deserialize(void *payload, const char *buffer, unsigned length) {
  (void)payload;
  (void)buffer;
  (void)length;
}

static bool is_name_start(int32_t c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }

static bool is_name_char(int32_t c) { return is_name_start(c) || (c >= '0' && c <= '9'); }

bool tree_sitter_tad_external_scanner_scan(void *payload, TSLexer *lexer, const bool *valid_symbols) {
  (void)payload;
  if (!valid_symbols[KEY]) return false;
  // the same whitespace as the grammar's extras
  while (lexer->lookahead == ' ' || lexer->lookahead == '\t' || lexer->lookahead == '\r' ||
         lexer->lookahead == '\n' || lexer->lookahead == '\f' || lexer->lookahead == 0xFEFF) {
    lexer->advance(lexer, true);
  }
  if (!is_name_start(lexer->lookahead)) return false;
  while (is_name_char(lexer->lookahead)) lexer->advance(lexer, false);
  lexer->mark_end(lexer);
  while (lexer->lookahead == ' ' || lexer->lookahead == '\t') lexer->advance(lexer, false);
  if (lexer->lookahead != ':') return false;
  lexer->result_symbol = KEY;
  return true;
}
