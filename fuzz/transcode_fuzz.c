/* libFuzzer target of the native transcoder (ros_gz_bridge_py/native/transcode.c), built with
 * AddressSanitizer and UndefinedBehaviorSanitizer (tests/unit/native/test_fuzz.py, `make fuzz`).
 *
 * The programs are every compiled pair's, from programs.h (tools/native_fuzz_programs.py
 * writes it at build time). The first input byte picks the mode:
 *   0x00-0x7f  transcode: program (byte % PROGRAM_COUNT) on the rest of the input as payload;
 *   0x80-0xbf  load: the rest is int32 words, the first of them the schema's length (modulo the
 *              words that follow), then schema and ops; when rgb_load accepts them, they are
 *              run on an empty payload and on the words' own bytes;
 *   0xc0-0xff  mutate: byte 1 picks a program, byte 2 (modulo 9) is a count of edits of 6
 *              bytes each (a word index, modulo the program's words, and the word's new value),
 *              the rest is a payload; when rgb_load accepts the edited words, they run on it.
 * Every status is legal; what is checked is that the code stays in bounds, defined, that an
 * RGB_OK output starts with the CDR header and keeps within the output bound, and that a
 * compiled program reads at most 8 fields a payload byte (its work stays linear). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "programs.h"
#include "transcode.h"
#include "wire.h"

#define MAX_WORDS 4096
#define MAX_EDITS 8

static struct rgb_program loaded[PROGRAM_COUNT];
static struct rgb_out out;

/* Returns the fields read (rgb_to_cdr's steps). */
static size_t transcode(const struct rgb_program *program, const uint8_t *payload, size_t n) {
    size_t steps = 0;
    enum rgb_status status = rgb_to_cdr(program, payload, n, &out, &steps);
    if (status > RGB_TOO_LARGE) abort();
    /* a refusal as too large only where even Python's most generous bound is passed */
    if (status == RGB_TOO_LARGE &&
        (out.refused.least == 0 || out.refused.items <= out.refuse_above / out.refused.least))
        abort();
    if (status == RGB_OK && (out.len < 4 || memcmp(out.data, "\0\1\0\0", 4) != 0)) abort();
    /* the output bound (wire.h) */
    if (status == RGB_OK && out.len > RGB_OUTPUT_FLOOR + RGB_OUTPUT_RATIO * n) abort();
    return steps;
}

/* Loads the words (a copy of exactly their length, so that ASan sees any read past them) and
 * runs what loads on the payload. */
static void load_and_run(const int32_t *words, size_t schema_len, size_t ops_len,
                         const uint8_t *payload, size_t n) {
    int32_t *schema = malloc((schema_len ? schema_len : 1) * sizeof *schema);
    int32_t *ops = malloc((ops_len ? ops_len : 1) * sizeof *ops);
    if (schema == NULL || ops == NULL) abort();
    memcpy(schema, words, schema_len * sizeof *schema);
    memcpy(ops, words + schema_len, ops_len * sizeof *ops);
    struct rgb_program program;
    const char *why = NULL;
    if (rgb_load(&program, schema, schema_len, ops, ops_len, &why) == 0) {
        transcode(&program, NULL, 0);
        transcode(&program, payload, n);
    } else if (why == NULL) {
        abort(); /* a refusal always says why */
    }
    free(schema);
    free(ops);
}

static void load_mode(const uint8_t *data, size_t size) {
    size_t count = size / 4;
    if (count == 0 || count > MAX_WORDS) return;
    int32_t words[MAX_WORDS];
    memcpy(words, data, count * 4);
    size_t rest = count - 1;
    size_t schema_len = (uint32_t)words[0] % (rest + 1);
    load_and_run(words + 1, schema_len, rest - schema_len, data, size);
}

static void mutate_mode(const uint8_t *data, size_t size) {
    if (size < 2) return;
    const struct fuzz_program *base = &PROGRAMS[data[0] % PROGRAM_COUNT];
    size_t edits = data[1] % (MAX_EDITS + 1);
    data += 2;
    size -= 2;
    if (size < 6 * edits) return;
    size_t total = base->schema_len + base->ops_len;
    if (total > MAX_WORDS) abort(); /* programs.h holds larger programs than expected */
    int32_t words[MAX_WORDS];
    memcpy(words, base->schema, base->schema_len * 4);
    memcpy(words + base->schema_len, base->ops, base->ops_len * 4);
    for (size_t k = 0; k < edits; k++, data += 6, size -= 6) {
        size_t at = (size_t)(data[0] | data[1] << 8) % total;
        memcpy(&words[at], data + 2, 4);
    }
    load_and_run(words, base->schema_len, base->ops_len, data, size);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size == 0) return 0;
    if (!(data[0] & 0x80)) {
        size_t i = data[0] % PROGRAM_COUNT;
        if (loaded[i].schema == NULL) {
            const char *why = NULL;
            if (rgb_load(&loaded[i], PROGRAMS[i].schema, PROGRAMS[i].schema_len, PROGRAMS[i].ops,
                         PROGRAMS[i].ops_len, &why))
                abort(); /* every compiled program loads */
        }
        /* libFuzzer's buffer ends where the input does: a read past the payload is caught. */
        size_t steps = transcode(&loaded[i], data + 1, size - 1);
        /* A compiled program's work is linear in the payload: a field takes 2 bytes or more,
         * and is read by validation, the index, and a few ops that go through a repeated
         * field's elements (docs/native.md §4). */
        if (steps > 8 * size + 64) abort();
    } else if (!(data[0] & 0x40)) {
        load_mode(data + 1, size - 1);
    } else {
        mutate_mode(data + 1, size - 1);
    }
    return 0;
}
