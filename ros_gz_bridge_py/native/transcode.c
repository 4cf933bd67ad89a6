/* The native transcoder (transcode.h; the format of its words: docs/native.md §2-§4): a
 * program run on a payload that pb_read.c validated and indexes, writing the CDR message.
 *
 * Every payload byte is untrusted: the output grows only by what the program writes for data
 * that is there, up to a bound proportional to the payload (output_limit), and a sequence that
 * could not fit is seen before it is written (rgb_least_bytes); anything this code is not sure
 * about is left to Python (RGB_FALLBACK). */
#include "transcode_ops.h"

#include <math.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>

/* ---- writing CDR -------------------------------------------------------------------------- */

/* Pads with zeros to `size`, counted from the end of the 4-byte encapsulation header. */
static int align(struct rgb_out *out, size_t size) {
    size_t pad = rgb_pad(out->len - 4, size);
    if (pad == 0) return 0;
    int status = rgb_grow(out, pad);
    if (status) return status;
    memset(out->data + out->len, 0, pad);
    out->len += pad;
    return 0;
}

static int put_u32(struct rgb_out *out, uint32_t value) {
    int status = align(out, 4);
    return status ? status : rgb_put_le(out, value, 4);
}

/* Writes `val` as ROS `kind` the way the Python path would, or RGB_FALLBACK where Python
 * would not write it this way (a value out of the type's range with `conv` exact). */
static int put_value(struct rgb_out *out, int32_t kind, int32_t conv, struct rgb_number val) {
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
    if (kind == ROS_BOOLEAN) return rgb_put_le(out, val.i != 0, 1);
    struct rgb_ros_type type = rgb_ros_type(kind);
    if (conv == CONV_EXACT && !rgb_in_range(val, type.min, type.max)) return RGB_FALLBACK;
    return rgb_put_le(out, bits, size);
}

/* A CDR string: length with the NUL, the bytes, the NUL; with `frame`, a Gazebo scoped name as
 * a ROS frame: each "::" (left to right) becomes "/". A NUL inside is left to Python. */
static int put_string(struct rgb_out *out, const uint8_t *p, size_t n, int frame) {
    if (n && memchr(p, 0, n) != NULL) return RGB_FALLBACK;
    size_t written = n;
    for (size_t i = 0; frame && i + 1 < n; i++) {
        if (p[i] == ':' && p[i + 1] == ':') {
            written--;
            i++;
        }
    }
    if (written >= UINT32_MAX) return RGB_FALLBACK;
    int status = put_u32(out, (uint32_t)written + 1);
    if (!status) status = frame ? rgb_grow(out, written) : rgb_put(out, p, n);
    if (status) return status;
    for (size_t i = 0; frame && i < n; i++) {
        int pair = p[i] == ':' && i + 1 < n && p[i + 1] == ':';
        out->data[out->len++] = pair ? '/' : p[i];
        i += (size_t)pair;
    }
    return rgb_put(out, "", 1);
}

/* ---- running a program ------------------------------------------------------------------- */

static int run(struct ctx *c, const int32_t *op, const int32_t *end, struct at v);

/* The string field `number` of `at` (its last occurrence; empty where it is absent). */
static int put_string_field(struct ctx *c, struct at at, uint32_t number) {
    struct field f;
    int found, status = pb_last_of(c, at, number, &f, &found);
    if (status) return status;
    if (found && f.wire != WIRE_LEN) return RGB_FALLBACK;
    return found ? put_string(c->out, f.payload.p, f.payload.n, 0) : put_string(c->out, NULL, 0, 0);
}

/* The scalar field `number` of protobuf `type` in `at`, written as ROS `kind`. */
static int put_scalar_field(struct ctx *c, struct at at, uint32_t number, int32_t type,
                            int32_t kind, int32_t conv) {
    struct rgb_number val;
    int status = pb_scalar(c, at, number, type, &val);
    return status ? status : put_value(c->out, kind, conv, val);
}

/* Counting, and then reading, the elements of a repeated scalar (packed or not). */
struct scalars {
    int32_t type;
    size_t count;
    int32_t kind; /* 0: count only */
    struct rgb_out *out;
};

/* One element: counted, and written as s->kind where there is one. */
static int scalar_one(struct scalars *s, const struct field *f) {
    s->count++;
    if (!s->kind) return 0;
    return put_value(s->out, s->kind, CONV_EXACT, pb_decode_scalar(s->type, pb_raw_of(f)));
}

static int scalar_element(void *ctx, const struct field *f) {
    struct scalars *s = ctx;
    int wire = rgb_wire_of(s->type), status = 0;
    if (f->wire != WIRE_LEN || wire == WIRE_LEN) /* one value, not a packed run */
        return f->wire == wire ? scalar_one(s, f) : RGB_FALLBACK;
    for (size_t pos = 0; pos < f->payload.n && !status;) {
        struct field one = {f->number, wire, 0, {NULL, 0}};
        status = read_value(f->payload, &pos, wire, &one);
        if (!status) status = scalar_one(s, &one);
    }
    return status;
}

/* Writes a fixed list of doubles given as one packed run of its length (a covariance, the
 * most common fixed list; Gazebo sends it as floats or doubles) in one pass over the run, each
 * value as put_value writes it. *written is 0 where the list is given otherwise (element by
 * element, in several runs, of another length): it is then read element by element. */
static int packed_doubles(struct ctx *c, struct at at, uint32_t number, int32_t type,
                          int32_t count, int *written) {
    size_t size = type == PB_DOUBLE ? 8 : 4, occurrences;
    struct field f;
    int found = 0;
    *written = 0;
    int status = pb_count_of(c, at, number, &occurrences);
    if (!status && occurrences == 1) status = pb_last_of(c, at, number, &f, &found);
    if (status || !found || f.wire != WIRE_LEN || f.payload.n != (size_t)count * size)
        return status;
    status = align(c->out, 8);
    if (!status) status = rgb_grow(c->out, (size_t)count * 8);
    if (status) return status;
    for (int32_t k = 0; k < count; k++) {
        struct rgb_number v = rgb_float_bits(rgb_le(f.payload.p + (size_t)k * size, size), size);
        memcpy(c->out->data + c->out->len, &v.d, 8);
        c->out->len += 8;
    }
    *written = 1;
    return 0;
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
    int status = m->type >= 0 ? pb_index_message(m->c, f->payload, m->type, &element.node) : 0;
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
};

static int column_element(void *ctx, const struct field *f) {
    struct column *c = ctx;
    struct at element;
    if (f->wire != WIRE_LEN) return RGB_FALLBACK;
    /* each element is read by one op only: scanned, not indexed */
    int status = pb_descend(c->c, (struct at){f->payload, NO_NODE}, c->steps, c->nsteps, &element);
    if (status) return status;
    if (c->kind == 0) return put_string_field(c->c, element, c->number);
    return put_scalar_field(c->c, element, c->number, c->type, c->kind, CONV_EXACT);
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
    int found_key, found_value, status = pb_find(h->c, f->payload, 1, 0, &key, &found_key);
    if (status) return status;
    if (found_key && key.wire != WIRE_LEN) return RGB_FALLBACK;
    struct view key_bytes = found_key ? key.payload : (struct view){NULL, 0};
    if (key_bytes.n != h->key_len || (h->key_len && memcmp(key_bytes.p, h->key, h->key_len)))
        return 0;
    /* value[0]: the first occurrence of field 2 */
    status = pb_find(h->c, f->payload, 2, 1, &value, &found_value);
    if (status || !found_value) return status;
    if (value.wire != WIRE_LEN) return RGB_FALLBACK;
    h->found = 1;
    h->value = value.payload;
    return 0;
}

/* Where the last path of a run led, step by step. A message's ops read its fields through
 * paths that share their first steps (pose.position.x, .y, .z), and a walk depends only on the
 * run's message and the steps (each submessage is indexed once and kept until the run ends), so
 * a shared beginning is walked once. */
#define KEPT_STEPS 8
struct walked {
    int32_t n;
    int32_t steps[KEPT_STEPS];
    struct at reached[KEPT_STEPS]; /* after each step */
};

/* The message `steps` reach from `v`, from where the last walk of the same run parted. */
static int descend(struct ctx *c, struct walked *w, struct at v, const int32_t *steps, int32_t n,
                   struct at *out) {
    int32_t same = 0;
    while (same < n && same < w->n && steps[same] == w->steps[same]) same++;
    struct at a = same ? w->reached[same - 1] : v;
    for (int32_t i = same; i < n; i++) {
        int status = pb_descend(c, a, steps + i, 1, &a);
        if (status) return status;
        if (i < KEPT_STEPS) {
            w->steps[i] = steps[i];
            w->reached[i] = a;
        }
    }
    w->n = n < KEPT_STEPS ? n : KEPT_STEPS;
    *out = a;
    return 0;
}

static int run(struct ctx *c, const int32_t *op, const int32_t *end, struct at v) {
    struct rgb_out *out = c->out;
    struct walked walked = {0};
    while (op < end && *op != OP_END) {
        int32_t code = *op++;
        struct at at;
        int status;
        const char *layout = rgb_layout(rgb_op_layouts, OP_COUNT, code);
        if (layout != NULL && layout[0] == 'P') { /* the message its path (count, steps) reaches */
            status = descend(c, &walked, v, op + 1, op[0], &at);
            if (status) return status;
            op += 1 + op[0];
        }
        switch (code) {
        case OP_NUM:
            status = put_scalar_field(c, at, (uint32_t)op[0], op[1], op[2], op[3]);
            op += 4;
            break;
        case OP_CONST: {
            uint64_t bits = (uint32_t)op[1] | (uint64_t)(uint32_t)op[2] << 32;
            size_t size = rgb_ros_size(op[0]);
            status = align(out, size);
            if (!status) status = rgb_put_le(out, bits, size);
            op += 3;
            break;
        }
        case OP_STR:
            status = put_string_field(c, at, (uint32_t)op[0]);
            op += 1;
            break;
        case OP_CONST_STR:
            status = put_string(out, word_bytes(op), (size_t)op[0], 0);
            op += rgb_text_span(op[0]);
            break;
        case OP_HEADER_STR: {
            struct header_lookup h = {c, word_bytes(op + 1), (size_t)op[1], op[0], 0, {NULL, 0}};
            op += 1 + rgb_text_span(op[1]);
            status = pb_for_each(c, at, 2, header_entry, &h);
            if (status) return status;
            status = h.found ? put_string(out, h.value.p, h.value.n, 1)
                             : put_string(out, word_bytes(op), (size_t)op[0], 0);
            op += rgb_text_span(op[0]);
            break;
        }
        case OP_FIXED_LIST: {
            uint32_t number = (uint32_t)op[0];
            int32_t type = op[1], kind = op[2], count = op[3];
            op += 4;
            if ((type == PB_DOUBLE || type == PB_FLOAT) && kind == ROS_DOUBLE) {
                int written;
                status = packed_doubles(c, at, number, type, count, &written);
                if (status || written) break;
            }
            struct scalars counting = {type, 0, 0, out};
            status = pb_for_each(c, at, number, scalar_element, &counting);
            if (status) return status;
            status = align(out, rgb_ros_size(kind));
            if (status) return status;
            if (counting.count == (size_t)count) {
                struct scalars writing = {type, 0, kind, out};
                status = pb_for_each(c, at, number, scalar_element, &writing);
            } else {
                struct rgb_number zero = {rgb_wire_of(type) != WIRE_VARINT, 0, 0, 0, 0.0};
                for (int32_t k = 0; k < count && !status; k++)
                    status = put_value(out, kind, CONV_EXACT, zero);
            }
            break;
        }
        case OP_SEQ_MSG: {
            uint32_t number = (uint32_t)op[0];
            int32_t body_len = op[1];
            const int32_t *body = op + 2;
            op = body + body_len;
            size_t count;
            status = pb_count_of(c, at, number, &count);
            if (status) return status;
            size_t least = rgb_least_bytes(body, body + body_len);
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
            struct messages m = {c, body, body + body_len, pb_element_type(c, at, number)};
            status = pb_for_each(c, at, number, message_element, &m);
            break;
        }
        case OP_COLUMN:
        case OP_COLUMN_STR: {
            uint32_t number = (uint32_t)op[0];
            int32_t nsub = op[1];
            struct column col = {c, op + 2, nsub, (uint32_t)op[2 + nsub], 0, 0};
            op += 3 + nsub;
            if (code == OP_COLUMN) {
                col.type = op[0];
                col.kind = op[1];
                op += 2;
            }
            size_t count;
            status = pb_count_of(c, at, number, &count);
            if (status) return status;
            status = sequence_start(out, count, code == OP_COLUMN ? rgb_ros_size(col.kind) : 0);
            if (status) return status;
            status = pb_for_each(c, at, number, column_element, &col);
            break;
        }
        case OP_CLOCK: {
            int32_t part = op[0];
            op += 1;
            struct rgb_number sec, nsec;
            status = pb_scalar(c, at, 1, PB_INT64, &sec);
            if (!status) status = pb_scalar(c, at, 2, PB_INT32, &nsec);
            if (status) return status;
            int64_t s = (int32_t)(uint32_t)(uint64_t)sec.i;
            if (s < 0) return RGB_CONVERSION;
            int64_t total = s * 1000000000LL + (int64_t)(uint32_t)(uint64_t)nsec.i;
            struct rgb_number result = {0, 0, 0, 0, 0.0};
            result.i = part == 0 ? (int32_t)(uint32_t)(uint64_t)(total / 1000000000LL)
                                 : total % 1000000000LL;
            status = put_value(out, part == 0 ? ROS_INT32 : ROS_UINT32, CONV_EXACT, result);
            break;
        }
        case OP_WALL_STAMP: { /* a Time of the wall clock now: int32 sec, uint32 nanosec */
            struct timespec now;
            clock_gettime(CLOCK_REALTIME, &now);
            if (now.tv_sec < 0 || now.tv_sec > INT32_MAX) return RGB_FALLBACK;
            struct rgb_number sec = {0, 0, (int64_t)now.tv_sec, 0, 0.0};
            struct rgb_number nsec = {0, 0, (int64_t)now.tv_nsec, 0, 0.0};
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

enum rgb_status rgb_to_cdr(const struct rgb_program *program, const uint8_t *payload,
                           size_t payload_len, struct rgb_out *out, size_t *steps) {
    static const uint8_t header[4] = {0, 1, 0, 0};
    struct view v = {payload, payload_len};
    struct ctx c = {program, out, 0, 0};
    rgb_trim(out); /* the last message's output is no longer used */
    out->len = 0;
    out->limit = output_limit(payload_len);
    out->refuse_above = refusal_limit(payload_len);
    struct at root = {v, NO_NODE};
    int status = pb_validate(&c, v, program->root, 0, &root.node);
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

void rgb_out_free(struct rgb_out *out) {
    free(out->data);
    free(out->scratch);
    out->data = NULL;
    out->scratch = NULL;
    out->len = out->cap = out->scratch_cap = 0;
}
