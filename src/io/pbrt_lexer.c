#define _POSIX_C_SOURCE 200809L
#include "io/pbrt_lexer.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "io/obj_check.h"

int cdl_pbrt_lexer_open(cdl_pbrt_lexer *lx, const char *path, cdl_error *err)
{
    memset(lx, 0, sizeof *lx);
    snprintf(lx->path, sizeof lx->path, "%s", path);
    int rc = cdl_read_text_file(path, &lx->buf, &lx->size, err);
    if (rc)
        return rc;
    struct stat st;
    if (stat(path, &st) == 0) {
        lx->dev = st.st_dev;
        lx->ino = st.st_ino;
    }
    lx->line = 1;
    /* A text file has no control bytes but whitespace: anything else is
     * binary data, reported where it starts rather than as a parse error. */
    int line = 1;
    for (size_t i = 0; i < lx->size; i++) {
        unsigned char ch = (unsigned char)lx->buf[i];
        if (ch == '\n')
            line++;
        else if ((ch < 0x20 && ch != '\t' && ch != '\r' && ch != '\f' && ch != '\v') || ch == 0x7f) {
            cdl_pbrt_lexer_close(lx);
            return cdl_error_set(err, CDL_ERR_INPUT, path, line,
                                 "binary data (byte 0x%02x): not a pbrt text file", ch);
        }
    }
    return 0;
}

void cdl_pbrt_lexer_close(cdl_pbrt_lexer *lx)
{
    free(lx->buf);
    lx->buf = NULL;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

static int is_delim(char c)
{
    return is_space(c) || c == '"' || c == '[' || c == ']' || c == '#' || c == 0;
}

/* Scans a quoted string in place: the contents are unescaped over the
 * buffer and NUL-terminated where the closing quote was. */
static int scan_string(cdl_pbrt_lexer *lx, cdl_pbrt_token *t, cdl_error *err)
{
    char *b = lx->buf;
    size_t i = lx->pos + 1, o = i;
    t->kind = CDL_PBRT_STRING;
    t->line = lx->line;
    t->s = b + i;
    for (;;) {
        if (i >= lx->size)
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t->line, "unterminated quoted string");
        char c = b[i];
        if (c == '\n')
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t->line,
                                 "newline inside a quoted string (missing closing '\"')");
        if (c == '"')
            break;
        if (c == '\\') {
            if (++i >= lx->size)
                return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t->line, "unterminated quoted string");
            switch (b[i]) {
            case 'b': c = '\b'; break;
            case 'f': c = '\f'; break;
            case 'n': c = '\n'; break;
            case 'r': c = '\r'; break;
            case 't': c = '\t'; break;
            case '\\': c = '\\'; break;
            case '\'': c = '\''; break;
            case '"': c = '"'; break;
            default:
                return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t->line,
                                     "unknown escape '\\%c' in a quoted string", b[i]);
            }
        }
        b[o++] = c;
        i++;
    }
    t->len = o - (size_t)(t->s - b);
    b[o] = 0; /* o <= i: overwrites at most the closing quote */
    lx->pos = i + 1;
    return 0;
}

int cdl_pbrt_next(cdl_pbrt_lexer *lx, cdl_pbrt_token *t, cdl_error *err)
{
    if (lx->has_peek) {
        *t = lx->peeked;
        lx->has_peek = 0;
        return 0;
    }
    const char *b = lx->buf;
    for (;;) {
        while (lx->pos < lx->size && is_space(b[lx->pos])) {
            if (b[lx->pos] == '\n')
                lx->line++;
            lx->pos++;
        }
        if (lx->pos < lx->size && b[lx->pos] == '#') {
            while (lx->pos < lx->size && b[lx->pos] != '\n')
                lx->pos++;
            continue;
        }
        break;
    }
    t->line = lx->line;
    t->len = 0;
    t->s = b + lx->pos;
    if (lx->pos >= lx->size) {
        t->kind = CDL_PBRT_EOF;
        return 0;
    }
    char c = b[lx->pos];
    if (c == '"')
        return scan_string(lx, t, err);
    if (c == '[' || c == ']') {
        t->kind = c == '[' ? CDL_PBRT_LBRACK : CDL_PBRT_RBRACK;
        t->len = 1;
        lx->pos++;
        return 0;
    }
    size_t start = lx->pos;
    while (lx->pos < lx->size && !is_delim(b[lx->pos]))
        lx->pos++;
    t->kind = CDL_PBRT_WORD;
    t->len = lx->pos - start;
    return 0;
}

int cdl_pbrt_peek(cdl_pbrt_lexer *lx, cdl_pbrt_token *t, cdl_error *err)
{
    if (!lx->has_peek) {
        int rc = cdl_pbrt_next(lx, &lx->peeked, err);
        if (rc)
            return rc;
        lx->has_peek = 1;
    }
    *t = lx->peeked;
    return 0;
}

int cdl_pbrt_is_word(const cdl_pbrt_token *t, const char *w)
{
    return t->kind == CDL_PBRT_WORD && strlen(w) == t->len && !memcmp(t->s, w, t->len);
}

int cdl_pbrt_word_number(const cdl_pbrt_token *t, double *v)
{
    if (t->kind != CDL_PBRT_WORD || t->len == 0 || t->len > 64)
        return -1;
    char tmp[72];
    memcpy(tmp, t->s, t->len);
    tmp[t->len] = 0;
    char c = tmp[0];
    /* only decimal literals: strtod would also take "nan", "inf" and hex,
     * but "nan"/"inf" are caught by the callers' finiteness check */
    if (!(c == '-' || c == '+' || c == '.' || (c >= '0' && c <= '9')) &&
        strcasecmp(tmp, "nan") && strcasecmp(tmp, "inf") && strcasecmp(tmp, "infinity"))
        return -1;
    char *end;
    errno = 0;
    double d = strtod(tmp, &end);
    if (end == tmp || *end)
        return -1;
    *v = d;
    return 0;
}

void cdl_pbrt_token_text(const cdl_pbrt_token *t, char *buf, size_t n)
{
    switch (t->kind) {
    case CDL_PBRT_EOF: snprintf(buf, n, "end of file"); break;
    case CDL_PBRT_LBRACK: snprintf(buf, n, "'['"); break;
    case CDL_PBRT_RBRACK: snprintf(buf, n, "']'"); break;
    case CDL_PBRT_STRING: snprintf(buf, n, "\"%.60s\"", t->s); break;
    default: snprintf(buf, n, "'%.*s'", (int)(t->len > 60 ? 60 : t->len), t->s); break;
    }
}
