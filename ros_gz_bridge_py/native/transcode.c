/* The native transcoder (transcode.h; the format of its words: docs/native.md).
 *
 * Every payload byte is untrusted: each read is checked against the end of its view before it
 * is made, lengths are compared with what remains before they are used, and the output grows
 * only by what the program writes for data that is there, up to a bound proportional to the
 * payload (output_limit). The work is linear in the payload too: each message the ops read is
 * scanned once into an index (struct node) that every op reads from. A payload is
 * first validated against the whole schema, as the Python protobuf runtime does when it
 * parses (UTF-8 of every string field, every nested message), so that what this code accepts
 * the Python path accepts too; anything it is not sure about is left to Python
 * (RGB_FALLBACK). */
#include "transcode.h"
#include "wire.h"

#include <math.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>

/* Ops of a program (docs/native.md §3). */
enum {
    OP_END = 0,
    OP_NUM = 1,
    OP_CONST = 2,
    OP_STR = 3,
    OP_CONST_STR = 4,
    OP_HEADER_STR = 5,
    OP_FIXED_LIST = 6,
    OP_SEQ_MSG = 7,
    OP_COLUMN = 8,
    OP_COLUMN_STR = 9,
    OP_CLOCK = 10,
    OP_CONST_BLOCK = 11,
    OP_WALL_STAMP = 12,
};

/* Deepest nesting validated natively; deeper payloads are left to Python. */
#define MAX_DEPTH 64
/* Longest path of field numbers in an op. */
#define MAX_STEPS 16

struct view {
    const uint8_t *p;
    size_t n;
};

/* A scalar as Python would hold it: an integer (signed, or unsigned above INT64_MAX) or a
 * float. */
struct value {
    int is_float;
    int is_unsigned;
    int64_t i;
    uint64_t u;
    double d;
};

/* ---- reading the wire --------------------------------------------------------------------- */

/* Reads a varint at *pos; 0 on success, RGB_UNDECODABLE when it is cut off or longer than 10
 * bytes. */
static int read_varint(struct view v, size_t *pos, uint64_t *out) {
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
 * of fields it read, its work (rgb_to_cdr_counted). */
struct ctx {
    const struct rgb_program *pr;
    struct rgb_out *out;
    size_t top;   /* bytes of out->scratch in use */
    size_t steps; /* fields read */
};

/* Reads the field at *pos. Groups and odd tags are left to Python. */
static int read_field(struct ctx *c, struct view v, size_t *pos, struct field *f) {
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
        return read_varint(v, pos, &f->varint);
    case WIRE_I64:
    case WIRE_I32: {
        size_t size = f->wire == WIRE_I64 ? 8 : 4;
        if (v.n - *pos < size) return RGB_UNDECODABLE;
        f->payload.p = v.p + *pos;
        f->payload.n = size;
        *pos += size;
        return 0;
    }
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

static uint32_t le32(const uint8_t *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t le64(const uint8_t *p) { return (uint64_t)le32(p) | (uint64_t)le32(p + 4) << 32; }

/* ---- the schema ---------------------------------------------------------------------------- */

/* The words of message type `msg`: its field count, then 4 words a field. */
static const int32_t *message_words(const struct rgb_program *pr, int32_t msg) {
    return pr->schema + pr->schema[1 + msg];
}

/* The index among message `m`'s fields of the one numbered `number`, or -1 when unknown. */
static int field_index(const int32_t *m, uint32_t number) {
    for (int32_t i = 0; i < m[0]; i++)
        if ((uint32_t)m[1 + 4 * i] == number) return (int)i;
    return -1;
}

/* Validates a packed run of scalars of `type`. */
static int validate_packed(struct view run, int32_t type) {
    int wire = rgb_wire_of(type);
    if (wire == WIRE_I64 || wire == WIRE_I32) {
        size_t size = wire == WIRE_I64 ? 8 : 4;
        return run.n % size ? RGB_UNDECODABLE : 0;
    }
    size_t pos = 0;
    uint64_t ignored;
    while (pos < run.n) {
        int status = read_varint(run, &pos, &ignored);
        if (status) return status;
    }
    return 0;
}

/* Validates message `v` of schema type `msg`, as the Python runtime's parse would. */
static int validate(struct ctx *c, struct view v, int32_t msg, int depth) {
    if (depth > MAX_DEPTH) return RGB_FALLBACK;
    const int32_t *m = message_words(c->pr, msg);
    /* Singular submessages seen, to leave merged duplicates to Python (bit per field). */
    uint64_t seen = 0;
    size_t pos = 0;
    while (pos < v.n) {
        struct field f;
        int status = read_field(c, v, &pos, &f);
        if (status) return status;
        int index = field_index(m, f.number);
        if (index < 0) continue; /* unknown: kept aside by the runtime, never an error */
        const int32_t *sf = m + 1 + 4 * index;
        int32_t type = sf[1], repeated = sf[2];
        int wire = rgb_wire_of(type);
        if (repeated && wire != WIRE_LEN && f.wire == WIRE_LEN) {
            status = validate_packed(f.payload, type);
            if (status) return status;
            continue;
        }
        if (f.wire != wire) return RGB_FALLBACK; /* parsed as unknown: not followed here */
        if (type == PB_STRING) {
            if (!rgb_utf8_valid(f.payload.p, f.payload.n)) return RGB_UNDECODABLE;
        } else if (type == PB_MESSAGE) {
            if (!repeated) {
                uint64_t bit = index < 64 ? (uint64_t)1 << index : 0;
                if (bit == 0 || (seen & bit)) return RGB_FALLBACK;
                seen |= bit;
            }
            status = validate(c, f.payload, sf[3], depth + 1);
            if (status) return status;
        } else if (type == PB_GROUP) {
            return RGB_FALLBACK;
        }
    }
    return 0;
}

/* ---- finding values (in a validated message) --------------------------------------------- */

/* The last occurrence of field `number` (a singular field: the one Python keeps), found by
 * scanning `v`; found 0 when absent. */
static int find_last(struct ctx *c, struct view v, uint32_t number, struct field *out,
                     int *found) {
    size_t pos = 0;
    *found = 0;
    while (pos < v.n) {
        struct field f;
        int status = read_field(c, v, &pos, &f);
        if (status) return status;
        if (f.number == number) {
            *out = f;
            *found = 1;
        }
    }
    return 0;
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

static struct node *node_at(struct ctx *c, size_t offset) {
    return (struct node *)((uint8_t *)c->out->scratch + offset);
}

/* Reserves an index for a message of type `msg` on the scratch stack, its slots empty. */
static int push_node(struct ctx *c, int32_t msg, size_t *offset) {
    const int32_t *m = message_words(c->pr, msg);
    size_t size = sizeof(struct node) + (size_t)m[0] * sizeof(struct slot);
    if (size > MAX_SCRATCH - c->top) return RGB_FALLBACK;
    size_t need = c->top + size;
    if (need > c->out->scratch_cap) {
        size_t cap = c->out->scratch_cap ? c->out->scratch_cap : 4096;
        while (cap < need) cap *= 2;
        void *data = realloc(c->out->scratch, cap);
        if (data == NULL) return RGB_FALLBACK;
        c->out->scratch = data;
        c->out->scratch_cap = cap;
    }
    *offset = c->top;
    c->top = need;
    struct node *n = node_at(c, *offset);
    n->msg = msg;
    for (int32_t i = 0; i < m[0]; i++)
        n->slots[i] = (struct slot){0, 0, 0, {0, 0, 0, {NULL, 0}}, NO_NODE};
    return 0;
}

/* Indexes `v`, a validated message of schema type `msg`, in one scan. */
static int index_message(struct ctx *c, struct view v, int32_t msg, size_t *offset) {
    int status = push_node(c, msg, offset);
    if (status) return status;
    const int32_t *m = message_words(c->pr, msg);
    size_t pos = 0;
    while (pos < v.n) {
        size_t start = pos;
        struct field f;
        status = read_field(c, v, &pos, &f);
        if (status) return status;
        int k = field_index(m, f.number);
        if (k < 0) continue;
        struct slot *s = &node_at(c, *offset)->slots[k];
        if (s->count++ == 0) s->first = start;
        s->end = pos;
        s->last = f;
    }
    return 0;
}

/* The slot of field `number` in the index of `a` (with the field's schema words in *sf), or
 * -1 where `a` has no index or its type no such field: then `a` is scanned. */
static int slot_of(struct ctx *c, struct at a, uint32_t number, const int32_t **sf) {
    if (a.node == NO_NODE) return -1;
    const int32_t *m = message_words(c->pr, node_at(c, a.node)->msg);
    int k = field_index(m, number);
    if (k >= 0 && sf != NULL) *sf = m + 1 + 4 * k;
    return k;
}

/* The last occurrence of field `number` in `a`; found 0 when absent. */
static int last_of(struct ctx *c, struct at a, uint32_t number, struct field *out, int *found) {
    int k = slot_of(c, a, number, NULL);
    if (k < 0) return find_last(c, a.v, number, out, found);
    const struct slot *s = &node_at(c, a.node)->slots[k];
    *found = s->count > 0;
    if (*found) *out = s->last;
    return 0;
}

/* The submessage reached through `steps` (an empty view where one is absent), indexed where
 * the schema gives its type (each submessage once, however many ops read it). */
static int descend(struct ctx *c, struct at a, const int32_t *steps, int32_t nsteps,
                   struct at *out) {
    for (int32_t i = 0; i < nsteps; i++) {
        const int32_t *sf = NULL;
        int k = slot_of(c, a, (uint32_t)steps[i], &sf);
        struct field f;
        int found, status = last_of(c, a, (uint32_t)steps[i], &f, &found);
        if (status) return status;
        if (!found) {
            a = (struct at){{NULL, 0}, NO_NODE};
            continue;
        }
        if (f.wire != WIRE_LEN) return RGB_FALLBACK; /* not what the program expects here */
        if (k < 0 || sf[1] != PB_MESSAGE) {
            a = (struct at){f.payload, NO_NODE};
            continue;
        }
        size_t child = node_at(c, a.node)->slots[k].child;
        if (child == NO_NODE) {
            status = index_message(c, f.payload, sf[3], &child);
            if (status) return status;
            node_at(c, a.node)->slots[k].child = child; /* the scratch may have moved */
        }
        a = (struct at){f.payload, child};
    }
    *out = a;
    return 0;
}

/* The value of one scalar element of protobuf `type` from its wire form. */
static struct value decode_scalar(int32_t type, const struct field *f, uint64_t raw) {
    struct value val = {0, 0, 0, 0, 0.0};
    switch (type) {
    case PB_DOUBLE: {
        uint64_t bits = raw;
        val.is_float = 1;
        memcpy(&val.d, &bits, 8);
        break;
    }
    case PB_FLOAT: {
        uint32_t bits = (uint32_t)raw;
        float x;
        memcpy(&x, &bits, 4);
        val.is_float = 1;
        val.d = (double)x;
        break;
    }
    case PB_INT64:
    case PB_SFIXED64:
        val.i = (int64_t)raw;
        break;
    case PB_UINT64:
    case PB_FIXED64:
        val.u = raw;
        val.is_unsigned = raw > INT64_MAX;
        val.i = (int64_t)raw;
        break;
    case PB_INT32:
    case PB_ENUM:
    case PB_SFIXED32:
        val.i = (int32_t)(uint32_t)raw;
        break;
    case PB_UINT32:
    case PB_FIXED32:
        val.i = (uint32_t)raw;
        break;
    case PB_BOOL:
        val.i = raw != 0;
        break;
    case PB_SINT32: {
        uint32_t n = (uint32_t)raw;
        val.i = (int32_t)((n >> 1) ^ (~(n & 1) + 1));
        break;
    }
    case PB_SINT64:
        val.i = (int64_t)((raw >> 1) ^ (~(raw & 1) + 1));
        break;
    default:
        break;
    }
    (void)f;
    return val;
}

/* The raw bits of a non-packed scalar field. */
static uint64_t raw_of(const struct field *f) {
    if (f->wire == WIRE_VARINT) return f->varint;
    if (f->wire == WIRE_I64) return le64(f->payload.p);
    return le32(f->payload.p);
}

/* ---- writing CDR -------------------------------------------------------------------------- */

/* Pads with zeros to `size`, counted from the end of the 4-byte encapsulation header. */
static int align(struct rgb_out *out, size_t size) {
    size_t pad = (size - (out->len - 4) % size) % size;
    int status = rgb_grow(out, pad);
    if (status) return status;
    memset(out->data + out->len, 0, pad);
    out->len += pad;
    return 0;
}

static int put_u32(struct rgb_out *out, uint32_t value) {
    int status = align(out, 4);
    if (status) return status;
    uint8_t b[4] = {(uint8_t)value, (uint8_t)(value >> 8), (uint8_t)(value >> 16),
                    (uint8_t)(value >> 24)};
    return rgb_put(out, b, 4);
}

/* Writes `val` as ROS `kind` the way the Python path would, or RGB_FALLBACK where Python
 * would not write it this way (a value out of the type's range with `conv` exact). */
static int put_value(struct rgb_out *out, int32_t kind, int32_t conv, struct value val) {
    size_t size = rgb_ros_size(kind);
    uint8_t b[8];
    int status = align(out, size);
    if (status) return status;
    if (kind == ROS_DOUBLE || kind == ROS_FLOAT) {
        if (!val.is_float) return RGB_FALLBACK;
        if (kind == ROS_DOUBLE) {
            memcpy(b, &val.d, 8);
        } else {
            float x = (float)val.d;
            if (isinf(x) && !isinf(val.d)) return RGB_FALLBACK;
            memcpy(b, &x, 4);
        }
        return rgb_put(out, b, size);
    }
    if (val.is_float) return RGB_FALLBACK;
    uint64_t bits = val.is_unsigned ? val.u : (uint64_t)val.i;
    if (kind == ROS_BOOL) {
        b[0] = val.i != 0;
        return rgb_put(out, b, 1);
    }
    if (conv == CONV_EXACT) {
        int ok;
        int64_t i = val.i;
        switch (kind) {
        case ROS_UINT8: ok = !val.is_unsigned && i >= 0 && i <= UINT8_MAX; break;
        case ROS_INT8: ok = !val.is_unsigned && i >= INT8_MIN && i <= INT8_MAX; break;
        case ROS_INT16: ok = !val.is_unsigned && i >= INT16_MIN && i <= INT16_MAX; break;
        case ROS_UINT16: ok = !val.is_unsigned && i >= 0 && i <= UINT16_MAX; break;
        case ROS_INT32: ok = !val.is_unsigned && i >= INT32_MIN && i <= INT32_MAX; break;
        case ROS_UINT32: ok = !val.is_unsigned && i >= 0 && i <= (int64_t)UINT32_MAX; break;
        case ROS_INT64: ok = !val.is_unsigned; break;
        case ROS_UINT64: ok = val.is_unsigned || i >= 0; break;
        default: ok = 0;
        }
        if (!ok) return RGB_FALLBACK;
    }
    for (size_t k = 0; k < size; k++) b[k] = (uint8_t)(bits >> (8 * k));
    return rgb_put(out, b, size);
}

/* A CDR string: length with the NUL, the bytes, the NUL. A NUL inside is left to Python. */
static int put_string(struct rgb_out *out, const uint8_t *p, size_t n) {
    if (n && memchr(p, 0, n) != NULL) return RGB_FALLBACK;
    if (n >= UINT32_MAX) return RGB_FALLBACK;
    int status = put_u32(out, (uint32_t)n + 1);
    if (status) return status;
    status = rgb_put(out, p, n);
    if (status) return status;
    uint8_t nul = 0;
    return rgb_put(out, &nul, 1);
}

/* A Gazebo scoped name as a ROS frame: each "::" (left to right) becomes "/". */
static int put_frame(struct rgb_out *out, struct view s) {
    if (s.n && memchr(s.p, 0, s.n) != NULL) return RGB_FALLBACK;
    size_t pairs = 0;
    for (size_t i = 0; i + 1 < s.n; i++) {
        if (s.p[i] == ':' && s.p[i + 1] == ':') {
            pairs++;
            i++;
        }
    }
    size_t written = s.n - pairs;
    if (written >= UINT32_MAX) return RGB_FALLBACK;
    int status = put_u32(out, (uint32_t)written + 1);
    if (status) return status;
    status = rgb_grow(out, written + 1);
    if (status) return status;
    for (size_t i = 0; i < s.n; i++) {
        if (s.p[i] == ':' && i + 1 < s.n && s.p[i + 1] == ':') {
            out->data[out->len++] = '/';
            i++;
        } else {
            out->data[out->len++] = s.p[i];
        }
    }
    out->data[out->len++] = 0;
    return 0;
}

/* ---- running a program ------------------------------------------------------------------- */

static int run(struct ctx *c, const int32_t *op, const int32_t *end, struct at v);

/* Reads the path at *op (count, then field numbers) and returns the message it reaches. */
static int path(struct ctx *c, const int32_t **op, struct at v, struct at *out) {
    int32_t nsteps = (*op)[0];
    int status = descend(c, v, *op + 1, nsteps, out);
    *op += 1 + nsteps;
    return status;
}

/* The value of singular scalar `number` of protobuf `type` in `v` (0 when absent). */
static int scalar(struct ctx *c, struct at v, uint32_t number, int32_t type, struct value *val) {
    struct field f;
    int found, status = last_of(c, v, number, &f, &found);
    if (status) return status;
    if (found && f.wire != rgb_wire_of(type)) return RGB_FALLBACK;
    *val = decode_scalar(type, &f, found ? raw_of(&f) : 0);
    return 0;
}

/* Calls `each(element)` for every element of repeated field `number` in `v`: with an index,
 * from the first element to the last only. */
typedef int (*element_fn)(void *ctx, const struct field *f);

static int for_each(struct ctx *c, struct at v, uint32_t number, element_fn each, void *arg) {
    size_t pos = 0, end = v.v.n;
    int k = slot_of(c, v, number, NULL);
    if (k >= 0) {
        const struct slot *s = &node_at(c, v.node)->slots[k];
        if (s->count == 0) return 0;
        pos = s->first;
        end = s->end;
    }
    while (pos < end) {
        struct field f;
        int status = read_field(c, v.v, &pos, &f);
        if (status) return status;
        if (f.number != number) continue;
        status = each(arg, &f);
        if (status) return status;
    }
    return 0;
}

/* Counting, and then reading, the elements of a repeated scalar (packed or not). */
struct scalars {
    int32_t type;
    size_t count;
    int32_t kind; /* 0: count only */
    struct rgb_out *out;
};

static int scalar_element(void *ctx, const struct field *f) {
    struct scalars *s = ctx;
    int wire = rgb_wire_of(s->type);
    if (f->wire == WIRE_LEN && wire != WIRE_LEN) {
        size_t pos = 0;
        while (pos < f->payload.n) {
            struct field one = {f->number, wire, 0, {NULL, 0}};
            if (wire == WIRE_VARINT) {
                int status = read_varint(f->payload, &pos, &one.varint);
                if (status) return status;
            } else {
                size_t size = wire == WIRE_I64 ? 8 : 4;
                if (f->payload.n - pos < size) return RGB_UNDECODABLE;
                one.payload.p = f->payload.p + pos;
                one.payload.n = size;
                pos += size;
            }
            s->count++;
            if (s->kind) {
                int status = put_value(s->out, s->kind, CONV_EXACT,
                                       decode_scalar(s->type, &one, raw_of(&one)));
                if (status) return status;
            }
        }
        return 0;
    }
    if (f->wire != wire) return RGB_FALLBACK;
    s->count++;
    if (!s->kind) return 0;
    return put_value(s->out, s->kind, CONV_EXACT, decode_scalar(s->type, f, raw_of(f)));
}

static int count_field(void *ctx, const struct field *f) {
    (void)f;
    (*(size_t *)ctx)++;
    return 0;
}

/* The number of occurrences of field `number` in `v`. */
static int count_of(struct ctx *c, struct at v, uint32_t number, size_t *count) {
    int k = slot_of(c, v, number, NULL);
    if (k >= 0) {
        *count = node_at(c, v.node)->slots[k].count;
        return 0;
    }
    *count = 0;
    return for_each(c, v, number, count_field, count);
}

/* The schema type of the elements of message field `number` of `v`, or -1 where unknown. */
static int32_t element_type(struct ctx *c, struct at v, uint32_t number) {
    const int32_t *sf = NULL;
    if (slot_of(c, v, number, &sf) < 0 || sf[1] != PB_MESSAGE) return -1;
    return sf[3];
}

/* The elements of a repeated submessage field, each indexed (when its type is known) and run
 * through a body of ops; the element's index is popped after. */
struct messages {
    struct ctx *c;
    const int32_t *body, *body_end;
    int32_t type;
};

static int message_element(void *ctx, const struct field *f) {
    struct messages *m = ctx;
    if (f->wire != WIRE_LEN) return RGB_FALLBACK;
    size_t mark = m->c->top;
    struct at element = {f->payload, NO_NODE};
    int status = m->type >= 0 ? index_message(m->c, f->payload, m->type, &element.node) : 0;
    if (!status) status = run(m->c, m->body, m->body_end, element);
    m->c->top = mark;
    return status;
}

/* One scalar (or string) of each element of a repeated submessage field: a column. */
struct column {
    struct ctx *c;
    const int32_t *steps;
    int32_t nsteps;
    uint32_t number;
    int32_t type, kind; /* kind 0: a string column */
    struct rgb_out *out;
};

static int column_element(void *ctx, const struct field *f) {
    struct column *c = ctx;
    struct at element;
    if (f->wire != WIRE_LEN) return RGB_FALLBACK;
    /* each element is read by one op only: scanned, not indexed */
    int status = descend(c->c, (struct at){f->payload, NO_NODE}, c->steps, c->nsteps, &element);
    if (status) return status;
    if (c->kind == 0) {
        struct field s;
        int found;
        status = find_last(c->c, element.v, c->number, &s, &found);
        if (status) return status;
        if (found && s.wire != WIRE_LEN) return RGB_FALLBACK;
        return found ? put_string(c->out, s.payload.p, s.payload.n) : put_string(c->out, NULL, 0);
    }
    struct value val;
    status = scalar(c->c, element, c->number, c->type, &val);
    if (status) return status;
    return put_value(c->out, c->kind, CONV_EXACT, val);
}

/* The count written before a sequence, and the alignment Fast CDR gives its elements only
 * when there are some (docs/cdr.md §3). */
static int sequence_start(struct rgb_out *out, size_t count, size_t element_size) {
    if (count > UINT32_MAX) return RGB_FALLBACK;
    int status = put_u32(out, (uint32_t)count);
    if (status) return status;
    return count && element_size > 4 ? align(out, element_size) : 0;
}

/* A Header's value for `key` (docs/native.md §3): the first or last `data` entry whose key is
 * `key` and that has a value; its first value. */
struct header_lookup {
    struct ctx *c;
    const uint8_t *key;
    size_t key_len;
    int last;
    int found;
    struct view value;
};

static int header_entry(void *ctx, const struct field *f) {
    struct header_lookup *h = ctx;
    if (h->found && !h->last) return 0;
    if (f->wire != WIRE_LEN) return RGB_FALLBACK; /* f->payload is only set for WIRE_LEN */
    struct field key, value;
    int found_key, status = find_last(h->c, f->payload, 1, &key, &found_key);
    if (status) return status;
    if (found_key && key.wire != WIRE_LEN) return RGB_FALLBACK;
    struct view key_bytes = found_key ? key.payload : (struct view){NULL, 0};
    if (key_bytes.n != h->key_len || (h->key_len && memcmp(key_bytes.p, h->key, h->key_len)))
        return 0;
    /* value[0]: the first occurrence of field 2 */
    size_t pos = 0;
    while (pos < f->payload.n) {
        status = read_field(h->c, f->payload, &pos, &value);
        if (status) return status;
        if (value.number == 2) {
            if (value.wire != WIRE_LEN) return RGB_FALLBACK;
            h->found = 1;
            h->value = value.payload;
            return 0;
        }
    }
    return 0;
}

/* The bytes of a string stored in words (count, then the bytes packed 4 a word). */
static const uint8_t *word_bytes(const int32_t *words) { return (const uint8_t *)(words + 1); }

/* The fewest bytes the ops of a body (checked by check_ops) write for one element, whatever
 * its values: a CDR string or sequence writes at least its 4-byte length, a number or a fixed
 * list its size; alignment is not counted. A sequence of `count` elements thus writes at least
 * `count` times this, which lets OP_SEQ_MSG see at once that it would pass the output bound
 * (a Pose_V of 4 M empty poses wrote 128 MiB of transforms, 0.9 s, before giving up). */
static size_t least_bytes(const int32_t *op, const int32_t *end) {
    size_t least = 0;
    while (op < end && *op != OP_END) {
        int32_t code = *op++;
        switch (code) {
        case OP_NUM:
            op += 1 + op[0]; /* the path */
            least += rgb_ros_size(op[2]);
            op += 4;
            break;
        case OP_CONST:
            least += rgb_ros_size(op[0]);
            op += 3;
            break;
        case OP_STR:
            op += 1 + op[0];
            least += 4;
            op += 1;
            break;
        case OP_CONST_STR:
            least += 4;
            op += rgb_text_span(op[0]);
            break;
        case OP_HEADER_STR:
            op += 1 + op[0];
            least += 4;
            op += 1;
            op += rgb_text_span(op[0]);
            op += rgb_text_span(op[0]);
            break;
        case OP_FIXED_LIST:
            op += 1 + op[0];
            least += (size_t)op[3] * rgb_ros_size(op[2]);
            op += 4;
            break;
        case OP_SEQ_MSG:
            op += 1 + op[0];
            least += 4;
            op += 2 + op[1];
            break;
        case OP_COLUMN:
        case OP_COLUMN_STR:
            op += 1 + op[0];
            op += 1;
            op += 1 + op[0];
            op += 1;
            if (code == OP_COLUMN) op += 2;
            least += 4;
            break;
        case OP_CLOCK:
            op += 1 + op[0];
            least += 4; /* one int32 or uint32 */
            op += 1;
            break;
        case OP_WALL_STAMP:
            least += 8;
            break;
        case OP_CONST_BLOCK:
            least += (size_t)op[1];
            op += 1 + rgb_text_span(op[1]);
            break;
        default:
            return least; /* rgb_load admits no other op */
        }
    }
    return least;
}

static int run(struct ctx *c, const int32_t *op, const int32_t *end, struct at v) {
    struct rgb_out *out = c->out;
    while (op < end && *op != OP_END) {
        int32_t code = *op++;
        struct at at;
        int status;
        switch (code) {
        case OP_NUM: {
            status = path(c, &op, v, &at);
            if (status) return status;
            struct value val;
            status = scalar(c, at, (uint32_t)op[0], op[1], &val);
            if (status) return status;
            status = put_value(out, op[2], op[3], val);
            op += 4;
            break;
        }
        case OP_CONST: {
            uint64_t bits = (uint32_t)op[1] | (uint64_t)(uint32_t)op[2] << 32;
            size_t size = rgb_ros_size(op[0]);
            uint8_t b[8];
            for (size_t k = 0; k < size; k++) b[k] = (uint8_t)(bits >> (8 * k));
            status = align(out, size);
            if (!status) status = rgb_put(out, b, size);
            op += 3;
            break;
        }
        case OP_STR: {
            status = path(c, &op, v, &at);
            if (status) return status;
            struct field f;
            int found;
            status = last_of(c, at, (uint32_t)op[0], &f, &found);
            if (status) return status;
            if (found && f.wire != WIRE_LEN) return RGB_FALLBACK;
            status = found ? put_string(out, f.payload.p, f.payload.n) : put_string(out, NULL, 0);
            op += 1;
            break;
        }
        case OP_CONST_STR:
            status = put_string(out, word_bytes(op), (size_t)op[0]);
            op += rgb_text_span(op[0]);
            break;
        case OP_HEADER_STR: {
            status = path(c, &op, v, &at);
            if (status) return status;
            struct header_lookup h = {c, word_bytes(op + 1), (size_t)op[1], op[0], 0, {NULL, 0}};
            op += 1 + rgb_text_span(op[1]);
            status = for_each(c, at, 2, header_entry, &h);
            if (status) return status;
            status = h.found ? put_frame(out, h.value)
                             : put_string(out, word_bytes(op), (size_t)op[0]);
            op += rgb_text_span(op[0]);
            break;
        }
        case OP_FIXED_LIST: {
            status = path(c, &op, v, &at);
            if (status) return status;
            uint32_t number = (uint32_t)op[0];
            int32_t type = op[1], kind = op[2], count = op[3];
            op += 4;
            struct scalars counting = {type, 0, 0, out};
            status = for_each(c, at, number, scalar_element, &counting);
            if (status) return status;
            status = align(out, rgb_ros_size(kind));
            if (status) return status;
            if (counting.count == (size_t)count) {
                struct scalars writing = {type, 0, kind, out};
                status = for_each(c, at, number, scalar_element, &writing);
            } else {
                struct value zero = {rgb_wire_of(type) != WIRE_VARINT, 0, 0, 0, 0.0};
                for (int32_t k = 0; k < count && !status; k++)
                    status = put_value(out, kind, CONV_EXACT, zero);
            }
            break;
        }
        case OP_SEQ_MSG: {
            status = path(c, &op, v, &at);
            if (status) return status;
            uint32_t number = (uint32_t)op[0];
            int32_t body_len = op[1];
            const int32_t *body = op + 2;
            op = body + body_len;
            size_t count;
            status = count_of(c, at, number, &count);
            if (status) return status;
            size_t least = least_bytes(body, body + body_len);
            if (least && count > out->refuse_above / least) {
                out->refused.items = count;
                out->refused.least = least;
                return RGB_TOO_LARGE; /* Python refuses it too, after a parse of every item */
            }
            size_t limit = out->limit && out->limit < RGB_MAX_OUTPUT ? out->limit : RGB_MAX_OUTPUT;
            if (least && (out->len > limit || count > (limit - out->len) / least))
                return RGB_FALLBACK; /* it could not fit: Python decides (and refuses) */
            status = sequence_start(out, count, 0);
            if (status) return status;
            struct messages m = {c, body, body + body_len, element_type(c, at, number)};
            status = for_each(c, at, number, message_element, &m);
            break;
        }
        case OP_COLUMN:
        case OP_COLUMN_STR: {
            status = path(c, &op, v, &at);
            if (status) return status;
            uint32_t number = (uint32_t)op[0];
            int32_t nsub = op[1];
            struct column col = {c, op + 2, nsub, (uint32_t)op[2 + nsub], 0, 0, out};
            op += 3 + nsub;
            if (code == OP_COLUMN) {
                col.type = op[0];
                col.kind = op[1];
                op += 2;
            }
            size_t count;
            status = count_of(c, at, number, &count);
            if (status) return status;
            status = sequence_start(out, count, code == OP_COLUMN ? rgb_ros_size(col.kind) : 0);
            if (status) return status;
            status = for_each(c, at, number, column_element, &col);
            break;
        }
        case OP_CLOCK: {
            status = path(c, &op, v, &at);
            if (status) return status;
            int32_t part = op[0];
            op += 1;
            struct value sec, nsec;
            status = scalar(c, at, 1, PB_INT64, &sec);
            if (!status) status = scalar(c, at, 2, PB_INT32, &nsec);
            if (status) return status;
            int64_t s = (int32_t)(uint32_t)(uint64_t)sec.i;
            if (s < 0) return RGB_CONVERSION;
            int64_t total = s * 1000000000LL + (int64_t)(uint32_t)(uint64_t)nsec.i;
            struct value result = {0, 0, 0, 0, 0.0};
            if (part == 0) {
                result.i = (int32_t)(uint32_t)(uint64_t)(total / 1000000000LL);
                status = put_value(out, ROS_INT32, CONV_EXACT, result);
            } else {
                result.i = total % 1000000000LL;
                status = put_value(out, ROS_UINT32, CONV_EXACT, result);
            }
            break;
        }
        case OP_WALL_STAMP: { /* a Time of the wall clock now: int32 sec, uint32 nanosec */
            struct timespec now;
            clock_gettime(CLOCK_REALTIME, &now);
            if (now.tv_sec < 0 || now.tv_sec > INT32_MAX) return RGB_FALLBACK;
            struct value sec = {0, 0, (int64_t)now.tv_sec, 0, 0.0};
            struct value nsec = {0, 0, (int64_t)now.tv_nsec, 0, 0.0};
            status = put_value(out, ROS_INT32, CONV_EXACT, sec);
            if (!status) status = put_value(out, ROS_UINT32, CONV_EXACT, nsec);
            break;
        }
        case OP_CONST_BLOCK: {
            status = align(out, (size_t)op[0]);
            if (!status) status = rgb_put(out, word_bytes(op + 1), (size_t)op[1]);
            op += 1 + rgb_text_span(op[1]);
            break;
        }
        default:
            return RGB_FALLBACK; /* rgb_load admits no other op */
        }
        if (status) return status;
    }
    return 0;
}

/* The largest CDR message written for a payload of `n` bytes (docs/native.md §4): a message
 * of defaults has a fixed part (RGB_OUTPUT_FLOOR covers every pair's), and beyond it each
 * payload byte may give at most RGB_OUTPUT_RATIO bytes; more is an amplification (a Pose_V of
 * empty poses gives 28-40 times its size), left to Python, which refuses it too; and never
 * more than RGB_OUTPUT_MAX. */
static size_t output_limit(size_t n) {
    if (n > (RGB_OUTPUT_MAX - RGB_OUTPUT_FLOOR) / RGB_OUTPUT_RATIO) return RGB_OUTPUT_MAX;
    return RGB_OUTPUT_FLOOR + RGB_OUTPUT_RATIO * n;
}

/* The most that Python's bound on a list (converters/_limits.py: the floor, and the ratio
 * times the size protobuf gives the parsed message) can allow for a payload of `n` bytes. That
 * size is at most twice `n` (a negative int32 sent in 5 bytes is re-encoded in 10; anything
 * else keeps its size or shrinks), and least_bytes counts no more than Python's smallest item
 * (no padding, no string terminators), so a list over this is refused by Python as well: it is
 * refused here without handing Python a payload to parse item by item (docs/native.md §4). */
static size_t refusal_limit(size_t n) {
    if (n > (RGB_OUTPUT_MAX - RGB_OUTPUT_FLOOR) / (2 * RGB_OUTPUT_RATIO)) return RGB_OUTPUT_MAX;
    return RGB_OUTPUT_FLOOR + 2 * RGB_OUTPUT_RATIO * n;
}

void rgb_out_trim(struct rgb_out *out) { rgb_trim(out); }

enum rgb_status rgb_to_cdr_counted(const struct rgb_program *program, const uint8_t *payload,
                                   size_t payload_len, struct rgb_out *out, size_t *steps) {
    static const uint8_t header[4] = {0, 1, 0, 0};
    struct view v = {payload, payload_len};
    struct ctx c = {program, out, 0, 0};
    rgb_trim(out); /* the last message's output is no longer used */
    out->len = 0;
    out->limit = output_limit(payload_len);
    out->refuse_above = refusal_limit(payload_len);
    struct at root = {v, NO_NODE};
    int status = validate(&c, v, program->root, 0);
    if (!status) status = index_message(&c, v, program->root, &root.node);
    if (!status) status = rgb_put(out, header, 4);
    if (!status) status = run(&c, program->ops, program->ops + program->ops_len, root);
    if (status) {
        rgb_trim(out);
    } else if (out->scratch_cap > RGB_KEEP_BYTES) { /* the output stays for the caller */
        free(out->scratch);
        out->scratch = NULL;
        out->scratch_cap = 0;
    }
    if (steps != NULL) *steps = c.steps;
    return (enum rgb_status)status;
}

enum rgb_status rgb_to_cdr(const struct rgb_program *program, const uint8_t *payload,
                           size_t payload_len, struct rgb_out *out) {
    return rgb_to_cdr_counted(program, payload, payload_len, out, NULL);
}

void rgb_out_free(struct rgb_out *out) {
    free(out->data);
    free(out->scratch);
    out->data = NULL;
    out->scratch = NULL;
    out->len = out->cap = out->scratch_cap = 0;
}

/* ---- loading: every word checked once ----------------------------------------------------- */

static int check_schema(const int32_t *s, size_t n, const char **why) {
    if (n < 1 || s[0] < 1 || (size_t)s[0] >= n) {
        *why = "schema: bad message count";
        return -1;
    }
    int32_t count = s[0];
    for (int32_t i = 0; i < count; i++) {
        int32_t at = s[1 + i];
        if (at < 1 + count || (size_t)at >= n || s[at] < 0 || s[at] > 64 ||
            (size_t)s[at] > (n - (size_t)at - 1) / 4) {
            *why = "schema: a message lies outside the words";
            return -1;
        }
        for (int32_t k = 0; k < s[at]; k++) {
            const int32_t *f = s + at + 1 + 4 * k;
            if (f[0] <= 0 || f[1] < PB_DOUBLE || f[1] > PB_SINT64 || (f[2] != 0 && f[2] != 1) ||
                (f[1] == PB_MESSAGE ? (f[3] < 0 || f[3] >= count) : f[3] != -1)) {
                *why = "schema: a field is not well-formed";
                return -1;
            }
        }
    }
    return 0;
}

static int check_pb_scalar(int32_t type) {
    return type >= PB_DOUBLE && type <= PB_SINT64 && type != PB_STRING && type != PB_GROUP &&
           type != PB_MESSAGE && type != PB_BYTES;
}

static int check_ros(int32_t kind) { return kind >= ROS_BOOL && kind <= ROS_DOUBLE; }

/* Checks a path at *at (advancing past it). */
static int check_path(const int32_t *ops, size_t n, size_t *at) {
    if (*at >= n || ops[*at] < 0 || ops[*at] > MAX_STEPS || (size_t)ops[*at] >= n - *at) return -1;
    for (int32_t k = 1; k <= ops[*at]; k++)
        if (ops[*at + (size_t)k] <= 0) return -1;
    *at += 1 + (size_t)ops[*at];
    return 0;
}

/* Checks that `k` more words exist at `at`. */

static int check_text(const int32_t *ops, size_t n, size_t *at) {
    if (rgb_room(n, *at, 1) || ops[*at] < 0) return -1;
    size_t span = rgb_text_span(ops[*at]);
    if (rgb_room(n, *at, span)) return -1;
    *at += span;
    return 0;
}

static int check_ops(const int32_t *ops, size_t n, int depth) {
    size_t at = 0;
    if (depth > MAX_DEPTH) return -1;
    while (at < n) {
        int32_t code = ops[at++];
        switch (code) {
        case OP_END:
            return at == n ? 0 : -1;
        case OP_NUM:
            if (check_path(ops, n, &at) || rgb_room(n, at, 4) || ops[at] <= 0 ||
                !check_pb_scalar(ops[at + 1]) || !check_ros(ops[at + 2]) ||
                (ops[at + 3] != CONV_EXACT && ops[at + 3] != CONV_WRAP))
                return -1;
            at += 4;
            break;
        case OP_CONST:
            if (rgb_room(n, at, 3) || !check_ros(ops[at])) return -1;
            at += 3;
            break;
        case OP_STR:
            if (check_path(ops, n, &at) || rgb_room(n, at, 1) || ops[at] <= 0) return -1;
            at += 1;
            break;
        case OP_CONST_STR:
            if (check_text(ops, n, &at)) return -1;
            break;
        case OP_HEADER_STR:
            if (check_path(ops, n, &at) || rgb_room(n, at, 1) || (ops[at] != 0 && ops[at] != 1))
                return -1;
            at += 1;
            if (check_text(ops, n, &at) || check_text(ops, n, &at)) return -1;
            break;
        case OP_FIXED_LIST:
            if (check_path(ops, n, &at) || rgb_room(n, at, 4) || ops[at] <= 0 ||
                !check_pb_scalar(ops[at + 1]) || !check_ros(ops[at + 2]) || ops[at + 3] < 0 ||
                ops[at + 3] > 1 << 20)
                return -1;
            at += 4;
            break;
        case OP_SEQ_MSG:
            if (check_path(ops, n, &at) || rgb_room(n, at, 2) || ops[at] <= 0 || ops[at + 1] < 1 ||
                rgb_room(n, at + 2, (size_t)ops[at + 1]) ||
                check_ops(ops + at + 2, (size_t)ops[at + 1], depth + 1))
                return -1;
            at += 2 + (size_t)ops[at + 1];
            break;
        case OP_COLUMN:
        case OP_COLUMN_STR: {
            if (check_path(ops, n, &at) || rgb_room(n, at, 1) || ops[at] <= 0) return -1;
            at += 1;
            if (check_path(ops, n, &at) || rgb_room(n, at, 1) || ops[at] <= 0) return -1;
            at += 1;
            if (code == OP_COLUMN) {
                if (rgb_room(n, at, 2) || !check_pb_scalar(ops[at]) || !check_ros(ops[at + 1]))
                    return -1;
                at += 2;
            }
            break;
        }
        case OP_CLOCK:
            if (check_path(ops, n, &at) || rgb_room(n, at, 1) || (ops[at] != 0 && ops[at] != 1))
                return -1;
            at += 1;
            break;
        case OP_WALL_STAMP:
            break;
        case OP_CONST_BLOCK:
            if (rgb_room(n, at, 1) || (ops[at] != 1 && ops[at] != 2 && ops[at] != 4 && ops[at] != 8))
                return -1;
            at += 1;
            if (check_text(ops, n, &at)) return -1;
            break;
        default:
            return -1;
        }
    }
    return -1; /* a body ends with OP_END */
}

int rgb_load(struct rgb_program *program, const int32_t *schema, size_t schema_len,
             const int32_t *ops, size_t ops_len, const char **why) {
    if (check_schema(schema, schema_len, why)) return -1;
    if (check_ops(ops, ops_len, 0)) {
        *why = "program: an op is not well-formed";
        return -1;
    }
    program->schema = schema;
    program->schema_len = schema_len;
    program->ops = ops;
    program->ops_len = ops_len;
    program->root = 0;
    return 0;
}
