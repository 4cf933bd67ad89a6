/* What the transcoder's files share (private: transcode.h is its interface): the structures a
 * call works with and the reading of protobuf wire data (the ops of a program, docs/native.md
 * §3, are numbered in codes.h). pb_read.c reads and indexes a payload, transcode.c runs a
 * program on it and writes the CDR message, transcode_load.c checks a program's words once. */
#ifndef RGB_TRANSCODE_OPS_H
#define RGB_TRANSCODE_OPS_H

#include "transcode.h"
#include "wire.h"

/* Deepest nesting validated natively; deeper payloads are left to Python. */
#define MAX_DEPTH 64

struct view {
    const uint8_t *p;
    size_t n;
};

/* ---- reading the wire --------------------------------------------------------------------- */

/* Reads a varint at *pos; 0 on success, RGB_UNDECODABLE when it is cut off or longer than 10
 * bytes. */
static inline int read_varint(struct view v, size_t *pos, uint64_t *out) {
    if (*pos < v.n && v.p[*pos] < 0x80) { /* most tags and lengths: one byte */
        *out = v.p[(*pos)++];
        return 0;
    }
    uint64_t result = 0;
    for (int shift = 0; shift < 70; shift += 7) {
        if (*pos >= v.n) return RGB_UNDECODABLE;
        uint8_t byte = v.p[(*pos)++];
        if (shift < 64) result |= (uint64_t)(byte & 0x7f) << shift;
        if (!(byte & 0x80)) {
            *out = result;
            return 0;
        }
    }
    return RGB_UNDECODABLE;
}

/* One field of a message: its number, wire type and where its value is. */
struct field {
    uint32_t number;
    int wire;
    uint64_t varint;     /* WIRE_VARINT */
    struct view payload; /* WIRE_LEN: the bytes; WIRE_I32/I64: the 4 or 8 bytes */
};

/* What one rgb_to_cdr call works with: the program, the output, the index of the messages it
 * reads (kept in out->scratch as a stack: each run of ops pops what it indexed) and the number
 * of fields it read, its work (rgb_to_cdr's steps). */
struct ctx {
    const struct rgb_program *pr;
    struct rgb_out *out;
    size_t top;   /* bytes of out->scratch in use */
    size_t steps; /* fields read */
};

/* Reads a value of wire type `wire` (a varint, or 4 or 8 bytes) at *pos into `f`. */
static inline int read_value(struct view v, size_t *pos, int wire, struct field *f) {
    if (wire == WIRE_VARINT) return read_varint(v, pos, &f->varint);
    size_t size = wire == WIRE_I64 ? 8 : 4;
    if (v.n - *pos < size) return RGB_UNDECODABLE;
    f->payload.p = v.p + *pos;
    f->payload.n = size;
    *pos += size;
    return 0;
}

/* Reads the field at *pos. Groups and odd tags are left to Python. */
static inline int read_field(struct ctx *c, struct view v, size_t *pos, struct field *f) {
    uint64_t tag;
    c->steps++;
    size_t start = *pos;
    int status = read_varint(v, pos, &tag);
    if (status) return status;
    if (*pos - start > 5 || tag > UINT32_MAX) return RGB_FALLBACK;
    f->number = (uint32_t)(tag >> 3);
    f->wire = (int)(tag & 7);
    if (f->number == 0) return RGB_FALLBACK;
    switch (f->wire) {
    case WIRE_VARINT:
    case WIRE_I64:
    case WIRE_I32:
        return read_value(v, pos, f->wire, f);
    case WIRE_LEN: {
        uint64_t length;
        size_t at = *pos;
        status = read_varint(v, pos, &length);
        if (status) return status;
        /* The runtime (upb) refuses a length of more than 5 bytes, as it does a tag. */
        if (*pos - at > 5) return RGB_FALLBACK;
        if (length > v.n - *pos) return RGB_UNDECODABLE;
        f->payload.p = v.p + *pos;
        f->payload.n = (size_t)length;
        *pos += (size_t)length;
        return 0;
    }
    default:
        return RGB_FALLBACK;
    }
}

/* ---- the index: each message read by the ops is scanned once ------------------------------ */

/* Ops read many fields of one message; scanning it for each would cost the ops times its size
 * (an Odometry followed by a megabyte of small unknown fields took 60-72 ms). So a message of
 * known type is scanned once into an index, which records per field of its schema type how
 * many occurrences there are, where the first starts and the last ends, and the last (the
 * value of a singular field); every op reads from it. */

#define NO_NODE SIZE_MAX
/* Most scratch bytes one payload may index; past them it is left to Python. Legitimate
 * programs index a few nodes per level of nesting, each at most 64 slots. */
#define MAX_SCRATCH ((size_t)64 << 20)
/* The index validation builds as it goes: three times what a pair's message with every singular
 * submessage present takes (the largest, a JointWrench, 5 KiB), so that a payload of a hundred
 * thousand submessages does not make it index them all. */
#define EAGER_SCRATCH ((size_t)16 << 10)

struct slot {
    size_t count;      /* occurrences of the field */
    size_t first, end; /* where the first starts (its tag) and the last ends */
    struct field last; /* the last occurrence */
    size_t child;      /* the index of `last` as a submessage once built, else NO_NODE */
};

struct node {
    int32_t msg;           /* schema type */
    struct slot slots[];   /* one per field of the type, in schema order */
};

/* A message the ops read: its bytes, and its index where it has one (NO_NODE: a view whose
 * type the schema does not give, e.g. reached through a path a damaged program names, read by
 * scanning it). */
struct at {
    struct view v;
    size_t node;
};

/* ---- reading a validated payload (pb_read.c) --------------------------------------------- */

/* Validates message `v` of schema type `msg`, as the Python runtime's parse would; with `node`,
 * indexes it in the same scan (*node), and its singular submessages while the index holds at
 * most EAGER_SCRATCH bytes (past that, a submessage is indexed when a path first reaches it). */
int pb_validate(struct ctx *c, struct view v, int32_t msg, int depth, size_t *node);
/* Indexes `v`, a validated message of schema type `msg`, in one scan. */
int pb_index_message(struct ctx *c, struct view v, int32_t msg, size_t *offset);
/* The last (or `first`) occurrence of field `number` in `v`, scanned (found 0 when absent). */
int pb_find(struct ctx *c, struct view v, uint32_t number, int first, struct field *out,
            int *found);
/* The same in `a`, from its index where it has one. */
int pb_last_of(struct ctx *c, struct at a, uint32_t number, struct field *out, int *found);
/* The submessage reached through `steps` (an empty view where one is absent). */
int pb_descend(struct ctx *c, struct at a, const int32_t *steps, int32_t nsteps, struct at *out);
/* One scalar element of protobuf `type` from its wire form, and a field's raw bits (not
 * packed). */
struct rgb_number pb_decode_scalar(int32_t type, uint64_t raw);
uint64_t pb_raw_of(const struct field *f);
/* The value of singular scalar `number` of protobuf `type` in `v` (0 when absent). */
int pb_scalar(struct ctx *c, struct at v, uint32_t number, int32_t type, struct rgb_number *val);
/* Calls `each(arg, element)` for every element of repeated field `number` in `v`. */
typedef int (*element_fn)(void *ctx, const struct field *f);
int pb_for_each(struct ctx *c, struct at v, uint32_t number, element_fn each, void *arg);
/* The occurrences of field `number` in `v`; the schema type of its elements where it is a
 * message field (-1: unknown). */
int pb_count_of(struct ctx *c, struct at v, uint32_t number, size_t *count);
int32_t pb_element_type(struct ctx *c, struct at v, uint32_t number);

/* ---- the program's words (transcode_load.c) --------------------------------------------- */

/* The bytes of a string stored in words (count, then the bytes packed 4 a word). */
static inline const uint8_t *word_bytes(const int32_t *words) { return (const uint8_t *)(words + 1); }
/* Each op's operands (wire.h rgb_operands), by op code (transcode_load.c). */
extern const char *const rgb_op_layouts[OP_COUNT];
/* The fewest bytes the ops of a body write for one element (see transcode_load.c). */
size_t rgb_least_bytes(const int32_t *op, const int32_t *end);

#endif
