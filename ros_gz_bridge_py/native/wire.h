/* What the two native transcoders share (transcode.c, encode.c; docs/native.md): the numbers
 * the Python compilers write (codes.h, written from codes.py at build time: ops, protobuf field
 * types, ROS basic types, conversions), and the helpers of both wire formats. Header-only: the
 * extension and the fuzz targets compile it into each. */
#ifndef RGB_WIRE_H
#define RGB_WIRE_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "codes.h"
#include "transcode.h"

/* Protobuf wire types. */
enum { WIRE_VARINT = 0, WIRE_I64 = 1, WIRE_LEN = 2, WIRE_SGROUP = 3, WIRE_EGROUP = 4, WIRE_I32 = 5 };

/* Largest message either transcoder writes. */
#define RGB_MAX_OUTPUT ((size_t)1 << 30)
/* rgb_to_cdr's bound on its output: RGB_OUTPUT_FLOOR + RGB_OUTPUT_RATIO x the payload's bytes
 * (docs/native.md §4; converters/limits.py applies the same to the Python path). */
#define RGB_OUTPUT_FLOOR ((size_t)64 << 10)
#define RGB_OUTPUT_RATIO 16
/* ... and never more than this, whatever the payload: the largest Gazebo message the bridge
 * takes by default (GZ_TRANSPORT_MAX_MESSAGE_SIZE), so no ROS message it builds is larger than
 * the largest it accepts (converters/_limits.py MAX_OUTPUT). */
#define RGB_OUTPUT_MAX ((size_t)128 << 20)

/* A number as Python holds it: an integer (signed, or unsigned above INT64_MAX) or a float. */
struct rgb_number {
    int is_float, is_unsigned;
    int64_t i;
    uint64_t u;
    double d;
};

/* A float (`size` 4) or double (8) from its bits, as Python holds it. */
static inline struct rgb_number rgb_float_bits(uint64_t bits, size_t size) {
    struct rgb_number n = {1, 0, 0, 0, 0.0};
    if (size == 8) {
        memcpy(&n.d, &bits, 8);
    } else {
        uint32_t low = (uint32_t)bits;
        float f;
        memcpy(&f, &low, 4);
        n.d = (double)f;
    }
    return n;
}

/* An unsigned 64-bit integer, as Python holds it. */
static inline struct rgb_number rgb_u64(uint64_t bits) {
    struct rgb_number n = {0, bits > INT64_MAX, (int64_t)bits, bits, 0.0};
    return n;
}

/* A ROS basic type: its wire size and, for an integer, the range of its values (min 0: an
 * unsigned one); all zero for a kind that is not one. */
struct rgb_ros_type {
    size_t size;
    int64_t min;
    uint64_t max;
};

static inline struct rgb_ros_type rgb_ros_type(int32_t kind) {
    static const struct rgb_ros_type types[ROS_DOUBLE + 1] = {
        [ROS_BOOLEAN] = {1, 0, 1},
        [ROS_UINT8] = {1, 0, UINT8_MAX},
        [ROS_INT8] = {1, INT8_MIN, INT8_MAX},
        [ROS_INT16] = {2, INT16_MIN, INT16_MAX},
        [ROS_UINT16] = {2, 0, UINT16_MAX},
        [ROS_INT32] = {4, INT32_MIN, INT32_MAX},
        [ROS_UINT32] = {4, 0, UINT32_MAX},
        [ROS_INT64] = {8, INT64_MIN, INT64_MAX},
        [ROS_UINT64] = {8, 0, UINT64_MAX},
        [ROS_FLOAT] = {4, 0, 0},
        [ROS_DOUBLE] = {8, 0, 0},
    };
    struct rgb_ros_type none = {0, 0, 0};
    return kind >= ROS_BOOLEAN && kind <= ROS_DOUBLE ? types[kind] : none;
}

/* The wire size of a ROS basic type (0: not one). */
static inline size_t rgb_ros_size(int32_t kind) { return rgb_ros_type(kind).size; }

/* Whether the integer `v` is within [min, max]. */
static inline int rgb_in_range(struct rgb_number v, int64_t min, uint64_t max) {
    return v.is_unsigned ? v.u <= max : v.i >= min && (v.i < 0 || (uint64_t)v.i <= max);
}

/* The wire type of a protobuf field type. */
static inline int rgb_wire_of(int32_t type) {
    switch (type) {
    case PB_DOUBLE:
    case PB_FIXED64:
    case PB_SFIXED64:
        return WIRE_I64;
    case PB_FLOAT:
    case PB_FIXED32:
    case PB_SFIXED32:
        return WIRE_I32;
    case PB_STRING:
    case PB_BYTES:
    case PB_MESSAGE:
        return WIRE_LEN;
    default:
        return WIRE_VARINT;
    }
}

/* Whether the bytes are well-formed UTF-8 (no overlong forms, no surrogates, at most
 * U+10FFFF), as the protobuf runtime requires of string fields and Python's decode of text. */
static inline int rgb_utf8_valid(const uint8_t *s, size_t n) {
    size_t i = 0;
    while (i < n) {
        uint8_t c = s[i];
        if (c < 0x80) {
            i++;
            continue;
        }
        size_t need;
        uint8_t lo = 0x80, hi = 0xbf;
        if (c >= 0xc2 && c <= 0xdf) {
            need = 1;
        } else if (c >= 0xe0 && c <= 0xef) {
            need = 2;
            if (c == 0xe0) lo = 0xa0;
            if (c == 0xed) hi = 0x9f;
        } else if (c >= 0xf0 && c <= 0xf4) {
            need = 3;
            if (c == 0xf0) lo = 0x90;
            if (c == 0xf4) hi = 0x8f;
        } else {
            return 0;
        }
        if (n - i - 1 < need || s[i + 1] < lo || s[i + 1] > hi) return 0;
        for (size_t k = 2; k <= need; k++)
            if ((s[i + k] & 0xc0) != 0x80) return 0;
        i += need + 1;
    }
    return 1;
}

/* Makes room for `extra` more bytes; RGB_FALLBACK past out->limit (or RGB_MAX_OUTPUT) or
 * without memory. */
static inline int rgb_grow(struct rgb_out *out, size_t extra) {
    size_t limit = out->limit && out->limit < RGB_MAX_OUTPUT ? out->limit : RGB_MAX_OUTPUT;
    if (out->len > limit || extra > limit - out->len) return RGB_FALLBACK;
    size_t need = out->len + extra;
    if (need <= out->cap) return 0;
    size_t cap = out->cap ? out->cap : 256;
    while (cap < need) cap = cap > RGB_MAX_OUTPUT / 2 ? RGB_MAX_OUTPUT : cap * 2;
    uint8_t *data = realloc(out->data, cap);
    if (data == NULL) return RGB_FALLBACK;
    out->data = data;
    out->cap = cap;
    return 0;
}

/* Makes room for `need` items of `size` bytes in the array at `array` (a pointer to it, NULL
 * before its first item) of `*cap` items, the capacity doubled from `first`: 0, or -1 without
 * memory (the array left as it was). */
static inline int rgb_reserve(void *array, size_t *cap, size_t need, size_t size, size_t first) {
    if (need <= *cap) return 0;
    void *items;
    memcpy(&items, array, sizeof items);
    size_t grown = *cap ? *cap : first;
    while (grown < need) grown *= 2;
    items = realloc(items, grown * size);
    if (items == NULL) return -1;
    memcpy(array, &items, sizeof items);
    *cap = grown;
    return 0;
}

/* Buffers above this size are freed once used instead of kept for the next message. */
#define RGB_KEEP_BYTES ((size_t)1 << 20)

/* Frees what of `out` grew past RGB_KEEP_BYTES (its contents are no longer needed), so that a
 * large message does not keep its memory for the small ones after it. */
static inline void rgb_trim(struct rgb_out *out) {
    if (out->cap > RGB_KEEP_BYTES) {
        free(out->data);
        out->data = NULL;
        out->len = out->cap = 0;
    }
    if (out->scratch_cap > RGB_KEEP_BYTES) {
        free(out->scratch);
        out->scratch = NULL;
        out->scratch_cap = 0;
    }
}

/* Appends `n` bytes. */
static inline int rgb_put(struct rgb_out *out, const void *bytes, size_t n) {
    int status = rgb_grow(out, n);
    if (status) return status;
    if (n) memcpy(out->data + out->len, bytes, n);
    out->len += n;
    return 0;
}

/* The padding that takes offset `at` to a multiple of `size`: a CDR alignment (1, 2, 4 or 8,
 * all the loaders admit) by a mask, as a division costs tens of cycles a value; any other size
 * in full. */
static inline size_t rgb_pad(size_t at, size_t size) {
    if (size && !(size & (size - 1))) return (size - (at & (size - 1))) & (size - 1);
    return size ? (size - at % size) % size : 0;
}

/* The `size` (at most 8) bytes at `b` as a little-endian number. */
static inline uint64_t rgb_le(const uint8_t *b, size_t size) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    /* a double's or a float's bits (most numbers read): the host's own order */
    if (size == 8) {
        uint64_t wide;
        memcpy(&wide, b, 8);
        return wide;
    }
    if (size == 4) {
        uint32_t narrow;
        memcpy(&narrow, b, 4);
        return narrow;
    }
#endif
    uint64_t bits = 0;
    for (size_t k = 0; k < size && k < 8; k++) bits |= (uint64_t)b[k] << (8 * k);
    return bits;
}

/* Appends the `size` low bytes of `bits`, little-endian. */
static inline int rgb_put_le(struct rgb_out *out, uint64_t bits, size_t size) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    if (size <= 8) return rgb_put(out, &bits, size); /* the low bytes come first */
#endif
    uint8_t b[8];
    for (size_t k = 0; k < size && k < 8; k++) b[k] = (uint8_t)(bits >> (8 * k));
    return rgb_put(out, b, size < 8 ? size : 8);
}

/* The words a string takes in a program (its length, then the bytes four to a word); counted
 * in size_t, so a damaged length near INT32_MAX cannot overflow. */
static inline size_t rgb_text_span(int32_t nbytes) { return 1 + ((size_t)nbytes + 3) / 4; }

/* 0 when `k` more words exist at `at` of `n`, else -1. */
static inline int rgb_room(size_t n, size_t at, size_t k) { return at <= n && k <= n - at ? 0 : -1; }

/* Longest path of field numbers in an op. */
#define MAX_STEPS 16
/* Most operands an op has. */
#define RGB_MAX_OPERANDS 8

/* The operands of one op, as both transcoders' ops are laid out (docs/native.md §3, §6): one
 * letter an operand in the op's layout, each letter one word unless said otherwise:
 *   w  any word                          k  a ROS kind
 *   f  a field number (> 0)              s  a protobuf scalar type (a number, not bytes)
 *   F  a protobuf field number (1 to 2^29 - 1: the tag keeps 3 bits for the wire type)
 *   c  0 or 1 (a conversion, a flag)     a  an alignment (1, 2, 4 or 8)
 *   S  a slot of a frame of `nslots` (-1: none)
 *   n, N, m  a count of 0 to 2^20, 2^24 or 4096
 *   P  a path: a count up to MAX_STEPS, then as many field numbers
 *   T  a text: its length, then its bytes four to a word (rgb_text_span)
 *   B  a body: its length (at least 1), then as many words, which the caller checks.
 * Checks the operands at *at of ops[0..n) and advances past them; where[i] is the index of
 * operand i's (first) word. 0, or -1 when one is not well-formed or past the words. The loaders
 * check every op with it once; what walks loaded ops again uses it to find their operands. */
static inline int rgb_operands(const int32_t *ops, size_t n, size_t *at, const char *layout,
                               int32_t nslots, size_t where[RGB_MAX_OPERANDS]) {
    for (size_t i = 0; layout[i] != '\0' && i < RGB_MAX_OPERANDS; i++) {
        if (rgb_room(n, *at, 1)) return -1;
        int32_t w = ops[*at];
        size_t span = 1;
        int ok;
        switch (layout[i]) {
        case 'w': ok = 1; break;
        case 'f': ok = w > 0; break;
        case 'F': ok = w >= 1 && w <= (1 << 29) - 1; break;
        case 'k': ok = w >= ROS_BOOLEAN && w <= ROS_DOUBLE; break;
        case 's': /* not a string, group, message or bytes */
            ok = (w >= PB_DOUBLE && w <= PB_BOOL) || (w >= PB_UINT32 && w <= PB_SINT64);
            break;
        case 'c': ok = w == 0 || w == 1; break;
        case 'a': ok = w == 1 || w == 2 || w == 4 || w == 8; break;
        case 'S': ok = w >= -1 && w < nslots; break;
        case 'n': ok = w >= 0 && w <= 1 << 20; break;
        case 'N': ok = w >= 0 && w <= 1 << 24; break;
        case 'm': ok = w >= 0 && w <= 4096; break;
        case 'P': ok = w >= 0 && w <= MAX_STEPS; span = 1 + (size_t)w; break;
        case 'T': ok = w >= 0; span = rgb_text_span(w); break;
        case 'B': ok = w >= 1; span = 1 + (size_t)w; break;
        default: ok = 0;
        }
        if (!ok || rgb_room(n, *at, span)) return -1;
        for (size_t k = 1; layout[i] == 'P' && k < span; k++)
            if (ops[*at + k] <= 0) return -1;
        where[i] = *at;
        *at += span;
    }
    return 0;
}

/* The layout of op `code` in `layouts` (`count` of them; NULL where there is no such op). */
static inline const char *rgb_layout(const char *const *layouts, size_t count, int32_t code) {
    return code >= 0 && (size_t)code < count ? layouts[code] : NULL;
}

/* Checks the ops of a body, [0, n), against their layouts (`count` of them), and the bodies in
 * them (an op's B operand; its frame has the slots of its m operand, if it has one, else
 * `nslots`), nested at most `max_depth` deep: each body ends with op 0 at its last word. 0 when
 * they are well-formed, else -1. Both loaders check their ops with it. */
static inline int rgb_check_body(const int32_t *ops, size_t n, const char *const *layouts,
                                 size_t count, int32_t nslots, int depth, int max_depth) {
    size_t at = 0, w[RGB_MAX_OPERANDS];
    if (depth > max_depth) return -1;
    while (at < n) {
        int32_t code = ops[at++];
        if (code == 0) return at == n ? 0 : -1;
        const char *layout = rgb_layout(layouts, count, code);
        if (layout == NULL || rgb_operands(ops, n, &at, layout, nslots, w)) return -1;
        const char *body = strchr(layout, 'B'), *slots = strchr(layout, 'm');
        if (body == NULL) continue;
        size_t b = w[body - layout];
        if (rgb_check_body(ops + b + 1, (size_t)ops[b], layouts, count,
                           slots != NULL ? ops[w[slots - layout]] : nslots, depth + 1, max_depth))
            return -1;
    }
    return -1;
}

#endif
