/* Tokenizer for pbrt scene files: quoted strings, bare words (directives,
 * numbers, v4 true/false), [ and ], with # comments; every token keeps
 * its line. One lexer per file; Include nests them in the loader. */
#ifndef CDL_PBRT_LEXER_H
#define CDL_PBRT_LEXER_H

#include <stddef.h>
#include <sys/types.h>

#include "core/error.h"

typedef enum cdl_pbrt_tok_kind {
    CDL_PBRT_EOF,
    CDL_PBRT_STRING, /* s: NUL-terminated contents, escapes resolved */
    CDL_PBRT_WORD,   /* s: start of the word, len bytes (not terminated) */
    CDL_PBRT_LBRACK,
    CDL_PBRT_RBRACK
} cdl_pbrt_tok_kind;

typedef struct cdl_pbrt_token {
    cdl_pbrt_tok_kind kind;
    const char *s;
    size_t len;
    int line;
} cdl_pbrt_token;

typedef struct cdl_pbrt_lexer {
    char *buf;
    size_t size, pos;
    int line;
    char path[1024];  /* for messages */
    dev_t dev;        /* identity of the file, for Include cycles */
    ino_t ino;
    cdl_pbrt_token peeked;
    int has_peek;
} cdl_pbrt_lexer;

/* Reads the whole file; rejects binary data with the line of the first
 * control byte. Errors name path (line 0 when the file cannot be read). */
int cdl_pbrt_lexer_open(cdl_pbrt_lexer *lx, const char *path, cdl_error *err);
void cdl_pbrt_lexer_close(cdl_pbrt_lexer *lx);
int cdl_pbrt_next(cdl_pbrt_lexer *lx, cdl_pbrt_token *t, cdl_error *err);
int cdl_pbrt_peek(cdl_pbrt_lexer *lx, cdl_pbrt_token *t, cdl_error *err);

/* Helpers on tokens. */
int cdl_pbrt_is_word(const cdl_pbrt_token *t, const char *w);
/* 0 and the value if t is a bare word that is a whole number literal
 * (NaN and infinities included: callers check finiteness). */
int cdl_pbrt_word_number(const cdl_pbrt_token *t, double *v);
/* Token text for messages ("end of file", "[", the word or string). */
void cdl_pbrt_token_text(const cdl_pbrt_token *t, char *buf, size_t n);

#endif
