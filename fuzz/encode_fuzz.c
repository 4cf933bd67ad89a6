/* libFuzzer target of the native encoder, ROS -> Gazebo (ros_gz_bridge_py/native/encode.c), built
 * with AddressSanitizer and UndefinedBehaviorSanitizer, and with MemorySanitizer
 * (tests/unit/native/test_fuzz.py, `make fuzz`).
 *
 * The encoders are every compiled pair's, from encoders.h (tools/native_fuzz_programs.py
 * --target encode writes it at build time). The first input byte picks the mode:
 *   0x00-0x7f  encode: encoder (byte % ENCODER_COUNT) on the rest of the input as a CDR message
 *              (its encapsulation header included);
 *   0x80-0xbf  load: the rest is int32 words, the first of them the encoder's length (modulo
 *              the words that follow), then the encoder's words; the bytes after them are a
 *              CDR body. When rgb_encoder_load accepts the words, they are run on a CDR header
 *              alone and on a CDR header followed by the body;
 *   0xc0-0xff  mutate: byte 1 picks an encoder, byte 2 (modulo 9) is a count of edits of 6
 *              bytes each (a word index, modulo the encoder's words, and the word's new value),
 *              the rest is a CDR message; when rgb_encoder_load accepts the edited words, they
 *              run on it.
 * Every status the encoder has is legal (RGB_OK, RGB_UNDECODABLE, RGB_FALLBACK); what is
 * checked is that the code stays in bounds, defined, and that an RGB_OK output is protobuf as
 * the runtime writes it: fields with valid tags and minimal varints, lengths within the
 * payload, every byte written (MemorySanitizer). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "encode.h"
#include "encoders.h"

#if defined(__has_feature)
#if __has_feature(memory_sanitizer)
#include <sanitizer/msan_interface.h>
#define CHECK_WRITTEN(p, n) __msan_check_mem_is_initialized((p), (n))
#endif
#endif
#ifndef CHECK_WRITTEN
#define CHECK_WRITTEN(p, n) ((void)(p), (void)(n))
#endif

#define MAX_WORDS 4096
#define MAX_EDITS 8

static struct rgb_encoder loaded[ENCODER_COUNT];
static struct rgb_out out;
static const uint8_t CDR_HEADER[4] = {0, 1, 0, 0};

/* A varint at *at, as the runtime writes it (at most 10 bytes, no trailing zero byte). */
static uint64_t varint(const uint8_t *p, size_t n, size_t *at) {
    uint64_t value = 0;
    for (int shift = 0; shift < 70; shift += 7) {
        if (*at >= n) abort(); /* cut short */
        uint8_t byte = p[(*at)++];
        if (shift == 63 && byte > 1) abort(); /* above 64 bits */
        value |= (uint64_t)(byte & 0x7f) << shift;
        if (!(byte & 0x80)) {
            if (byte == 0 && shift > 0) abort(); /* not minimal: Python writes fewer bytes */
            return value;
        }
    }
    abort(); /* longer than 10 bytes */
}

/* Aborts unless p[0..n) is a sequence of well-formed protobuf fields. */
static void check_wire(const uint8_t *p, size_t n) {
    size_t at = 0;
    while (at < n) {
        uint64_t tag = varint(p, n, &at);
        if (tag >> 3 == 0 || tag >> 3 > (1u << 29) - 1) abort();
        switch (tag & 7) {
        case 0:
            varint(p, n, &at);
            break;
        case 1:
            if (n - at < 8) abort();
            at += 8;
            break;
        case 2: {
            uint64_t length = varint(p, n, &at);
            if (length > n - at) abort();
            at += (size_t)length;
            break;
        }
        case 5:
            if (n - at < 4) abort();
            at += 4;
            break;
        default:
            abort();
        }
    }
}

static void encode(const struct rgb_encoder *encoder, const uint8_t *cdr, size_t n) {
    enum rgb_status status = rgb_to_pb(encoder, cdr, n, &out);
    if (status != RGB_OK && status != RGB_UNDECODABLE && status != RGB_FALLBACK) abort();
    if (status != RGB_OK) return;
    CHECK_WRITTEN(out.data, out.len);
    check_wire(out.data, out.len);
}

/* Loads the words (a copy of exactly their length, so that ASan sees any read past them) and
 * runs what loads on a CDR header alone and on `cdr`. */
static void load_and_run(const int32_t *words, size_t len, const uint8_t *cdr, size_t n) {
    int32_t *copy = malloc((len ? len : 1) * sizeof *copy);
    if (copy == NULL) abort();
    memcpy(copy, words, len * sizeof *copy);
    struct rgb_encoder encoder;
    const char *why = NULL;
    if (rgb_encoder_load(&encoder, copy, len, &why) == 0) {
        encode(&encoder, CDR_HEADER, sizeof CDR_HEADER);
        encode(&encoder, cdr, n);
    } else if (why == NULL) {
        abort(); /* a refusal always says why */
    }
    free(copy);
}

static void load_mode(const uint8_t *data, size_t size) {
    if (size < 4) return;
    uint32_t first;
    memcpy(&first, data, 4);
    size_t len = first % (size / 4); /* words after the first */
    if (len > MAX_WORDS) return;
    int32_t words[MAX_WORDS];
    memcpy(words, data + 4, len * 4);
    size_t body = size - 4 - len * 4;
    uint8_t *cdr = malloc(sizeof CDR_HEADER + body);
    if (cdr == NULL) abort();
    memcpy(cdr, CDR_HEADER, sizeof CDR_HEADER);
    memcpy(cdr + sizeof CDR_HEADER, data + 4 + len * 4, body);
    load_and_run(words, len, cdr, sizeof CDR_HEADER + body);
    free(cdr);
}

static void mutate_mode(const uint8_t *data, size_t size) {
    if (size < 2) return;
    const struct fuzz_encoder *base = &ENCODERS[data[0] % ENCODER_COUNT];
    size_t edits = data[1] % (MAX_EDITS + 1);
    data += 2;
    size -= 2;
    if (size < 6 * edits) return;
    if (base->len > MAX_WORDS) abort(); /* encoders.h holds larger encoders than expected */
    int32_t words[MAX_WORDS];
    memcpy(words, base->words, base->len * 4);
    for (size_t k = 0; k < edits; k++, data += 6, size -= 6) {
        size_t at = (size_t)(data[0] | data[1] << 8) % base->len;
        memcpy(&words[at], data + 2, 4);
    }
    load_and_run(words, base->len, data, size);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size == 0) return 0;
    if (!(data[0] & 0x80)) {
        size_t i = data[0] % ENCODER_COUNT;
        if (loaded[i].read_ops == NULL) {
            const char *why = NULL;
            if (rgb_encoder_load(&loaded[i], ENCODERS[i].words, ENCODERS[i].len, &why))
                abort(); /* every compiled encoder loads */
        }
        /* libFuzzer's buffer ends where the input does: a read past the message is caught. */
        encode(&loaded[i], data + 1, size - 1);
    } else if (!(data[0] & 0x40)) {
        load_mode(data + 1, size - 1);
    } else {
        mutate_mode(data + 1, size - 1);
    }
    return 0;
}
