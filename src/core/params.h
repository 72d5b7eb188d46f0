/* Parameter tables: every setting a user can give is one row (name, type,
 * default, range or choices, help, where it lands). A method declares its
 * rows once in its own source and lists the tables it reads in its vtable;
 * parsing, validation, defaults, help, the README's option tables and
 * Python's discovery all read them (as pbrt's ParameterDictionary and a
 * Mitsuba plugin's constructor do, with defaults in one place). */
#ifndef CDL_PARAMS_H
#define CDL_PARAMS_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

typedef enum {
    CDL_PARAM_INT,    /* an integer in [min, max]; `word` may stand for values[0] */
    CDL_PARAM_FLOAT,  /* a finite number in [min, max] (open ends: flags) */
    CDL_PARAM_BOOL,   /* on|off (1|0, true|false) */
    CDL_PARAM_CHOICE, /* one of the |-separated choices: its index, or values[index] */
    CDL_PARAM_FLOATS, /* count comma-separated finite numbers, each in [min, max] */
    CDL_PARAM_RES,    /* WIDTHxHEIGHT, each in [1, max] */
    CDL_PARAM_NAME    /* a word (the integrator), checked by its reader */
} cdl_param_type;

/* How the field a row lands in is stored (from its C type, CDL_PARAM_AT). */
typedef enum {
    CDL_STORE_NONE, /* a NAME's char buffer */
    CDL_STORE_INT,
    CDL_STORE_LONG,
    CDL_STORE_U32,
    CDL_STORE_U64,
    CDL_STORE_FLOAT,
    CDL_STORE_DOUBLE
} cdl_param_store;

enum {
    CDL_PARAM_OPEN_MIN = 1,  /* min itself is refused */
    CDL_PARAM_OPEN_MAX = 2,  /* max itself is refused */
    CDL_PARAM_FLAG = 4,      /* a bare switch: given without a value it means on */
    CDL_PARAM_REPEAT = 8,    /* each setting adds one more value (up to `repeat`), counted at count_at */
    CDL_PARAM_BITS = 16      /* CHOICE: the values are bits, OR'ed over repeated settings */
};

typedef struct cdl_param {
    const char *name;    /* library spelling: "max_radius" (the command line's max_radius) */
    cdl_param_type type;
    const char *meta;    /* what it takes, for help: "R", "WxH", "on|off" */
    const char *def;     /* default as text; "" when the method derives it (the help says how) */
    const char *help;    /* one line, unwrapped */
    double min, max;     /* INT, FLOAT, FLOATS: the range; RES: max is the largest side */
    const char *choices; /* CHOICE: "box|cone|epanechnikov"; INT: a word accepted too ("sample") */
    const double *values; /* CHOICE: stored per choice (NULL: its index); INT: the word's value */
    const char *unit;    /* "s", "MiB", "deg", "" */
    const char *note;    /* said when a value is out of range (why the range is what it is) */
    /* FLOATS: a check on the values together; returns the problem or NULL */
    const char *(*check)(const double *v, int n);
    /* NAME: a check on the text; returns the problem or NULL */
    const char *(*check_text)(const char *v);
    int flags;
    int count;           /* FLOATS: values per setting; RES: 2; NAME: the buffer's size */
    int repeat;          /* REPEAT: most settings */
    size_t at;           /* where it lands: offset in the struct the table is read into */
    int store;           /* cdl_param_store of the field (of one value for FLOATS/RES) */
    size_t count_at;     /* REPEAT: offset of the int that counts the settings */
} cdl_param;

typedef struct cdl_param_table {
    const char *title; /* the help section: "Photon mapping (pm; Jensen 1996 ...)" */
    const cdl_param *rows;
    int count;
} cdl_param_table;

#define CDL_STORE_OF(x)                                                                                 \
    _Generic((x), int: CDL_STORE_INT, long: CDL_STORE_LONG, unsigned int: CDL_STORE_U32,               \
             unsigned long: CDL_STORE_U64, float: CDL_STORE_FLOAT, double: CDL_STORE_DOUBLE,           \
             float *: CDL_STORE_FLOAT, int *: CDL_STORE_INT, default: CDL_STORE_NONE)
/* .at and .store of a row landing in field (a member path) of struct T */
#define CDL_PARAM_AT(T, field) .at = offsetof(T, field), .store = CDL_STORE_OF(((T *)0)->field)
#define CDL_PARAM_TABLE(title, rows) {title, rows, (int)(sizeof rows / sizeof *rows)}

/* Checks value against p and, if base is not NULL, stores it at base +
 * p->at. value NULL means on for a BOOL and the FLAG rows (else an error).
 * Errors name p->name (as err->file) and the problem. */
int cdl_param_set(const cdl_param *p, const char *value, void *base, cdl_error *err);

/* Stores every default of t into base (rows whose def is "" are left as
 * they are: zero means "derived" to their readers). */
void cdl_param_defaults(const cdl_param_table *t, void *base);

/* The row of t called name, or NULL. */
const cdl_param *cdl_param_find(const cdl_param_table *t, const char *name);

/* The choices of a CHOICE row (or an INT row's word), one per call:
 * returns the length of choice i and points *s at it, 0 past the end. */
int cdl_param_choice(const cdl_param *p, int i, const char **s);

#endif
