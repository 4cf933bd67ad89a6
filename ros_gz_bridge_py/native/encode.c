/* The native transcoder, ROS -> Gazebo (encode.h; the words: docs/native.md §6).
 *
 * Every CDR byte is untrusted: each read is checked against the end of the message before it
 * is made, counts are checked against the bytes that remain before anything is sized from
 * them, and the slots and the output grow only with data that is there (with hard caps). What
 * the Python path might read otherwise (another encapsulation, a string without its NUL or
 * with one inside, text that is not UTF-8, a bool that is neither 0 nor 1, a number out of the
 * protobuf field's range) is left to it (RGB_FALLBACK). A sequence's count is checked against
 * the fewest bytes its elements take before any slot is made for them. */
#include "encode.h"
#include "wire.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    R_END = 0,
    R_NUM = 1,
    R_STR = 2,
    R_ARR = 3,
    R_SEQ_NUM = 4,
    R_SEQ_STR = 5,
    R_SEQ_MSG = 6,
};

enum {
    W_END = 0,
    W_NUM = 1,
    W_STR = 2,
    W_STR_REP = 3,
    W_CONST_STR = 4,
    W_MSG = 5,
    W_SEQ_MSG = 6,
    W_PACKED = 7,
    W_SEQ_STR = 8,
};

/* Slots of one message at most (40 bytes each): beyond, Python decides. */
#define MAX_SLOTS ((size_t)1 << 22)
#define MAX_DEPTH 32

/* A field kept for the write ops: a number's raw bits, or where the data is. */
struct slot {
    uint64_t bits;
    size_t offset; /* strings, arrays, sequences: where the data starts in the CDR */
    size_t count;  /* strings: bytes (without the NUL); arrays, sequences: elements; message
                      sequences: elements, whose frames start at `frame` */
    size_t frame;
};

struct reader {
    const uint8_t *p;
    size_t n, pos;
    struct slot *pool;
    size_t used, cap;
};

/* ---- reading CDR -------------------------------------------------------------------------- */

static int cdr_align(struct reader *r, size_t size) {
    size_t pad = (size - (r->pos - 4) % size) % size;
    if (r->n - r->pos < pad) return RGB_UNDECODABLE;
    r->pos += pad;
    return 0;
}

static int cdr_u32(struct reader *r, uint32_t *value) {
    int status = cdr_align(r, 4);
    if (status) return status;
    if (r->n - r->pos < 4) return RGB_UNDECODABLE;
    const uint8_t *b = r->p + r->pos;
    *value = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    r->pos += 4;
    return 0;
}

static uint64_t load(const uint8_t *b, size_t size) {
    uint64_t bits = 0;
    for (size_t k = 0; k < size; k++) bits |= (uint64_t)b[k] << (8 * k);
    return bits;
}

/* A string: its bytes without the NUL, as Python reads them. */
static int cdr_string(struct reader *r, struct slot *s) {
    uint32_t length;
    int status = cdr_u32(r, &length);
    if (status) return status;
    if (length > r->n - r->pos) return RGB_UNDECODABLE;
    if (length == 0) return RGB_FALLBACK;
    const uint8_t *text = r->p + r->pos;
    if (text[length - 1] != 0 || memchr(text, 0, length - 1) != NULL) return RGB_FALLBACK;
    if (!rgb_utf8_valid(text, length - 1)) return RGB_FALLBACK;
    if (s != NULL) {
        s->offset = r->pos;
        s->count = length - 1;
    }
    r->pos += length;
    return 0;
}

static int cdr_number(struct reader *r, int32_t kind, struct slot *s) {
    size_t size = rgb_ros_size(kind);
    int status = cdr_align(r, size);
    if (status) return status;
    if (r->n - r->pos < size) return RGB_UNDECODABLE;
    uint64_t bits = load(r->p + r->pos, size);
    if (kind == ROS_BOOL && bits > 1) return RGB_FALLBACK;
    if (s != NULL) s->bits = bits;
    r->pos += size;
    return 0;
}

/* `count` numbers of `kind` (aligned to their size when there are some). */
static int cdr_numbers(struct reader *r, int32_t kind, size_t count, struct slot *s) {
    size_t size = rgb_ros_size(kind);
    if (count) {
        int status = cdr_align(r, size);
        if (status) return status;
    }
    if (count > (r->n - r->pos) / size) return RGB_UNDECODABLE;
    if (kind == ROS_BOOL)
        for (size_t k = 0; k < count; k++)
            if (r->p[r->pos + k] > 1) return RGB_FALLBACK;
    if (s != NULL) {
        s->offset = r->pos;
        s->count = count;
    }
    r->pos += count * size;
    return 0;
}

static struct slot *frame_slot(struct reader *r, size_t frame, int32_t index) {
    return index < 0 ? NULL : &r->pool[frame + (size_t)index];
}

static int new_frames(struct reader *r, size_t count, int32_t nslots, size_t *first) {
    if (nslots && count > (MAX_SLOTS - r->used) / (size_t)nslots) return RGB_FALLBACK;
    size_t need = r->used + count * (size_t)nslots;
    if (need > r->cap) {
        size_t cap = r->cap ? r->cap : 64;
        while (cap < need) cap *= 2;
        struct slot *pool = realloc(r->pool, cap * sizeof *pool);
        if (pool == NULL) return RGB_FALLBACK;
        r->pool = pool;
        r->cap = cap;
    }
    /* nothing to clear for frames without slots (the pool may still be NULL then) */
    if (need > r->used) memset(r->pool + r->used, 0, (need - r->used) * sizeof *r->pool);
    *first = r->used;
    r->used = need;
    return 0;
}

/* The fewest bytes a message read by ops [op, end) takes on the wire (alignment aside): a
 * lower bound that keeps a count from sizing more slots than the bytes can hold. */
static size_t min_size(const int32_t *op, const int32_t *end) {
    size_t size = 0;
    while (op < end && *op != R_END) {
        switch (*op++) {
        case R_NUM:
            size += rgb_ros_size(op[0]);
            op += 2;
            break;
        case R_STR:
            size += 5; /* the length and the NUL */
            op += 1;
            break;
        case R_ARR:
            size += rgb_ros_size(op[0]) * (size_t)op[1];
            op += 3;
            break;
        case R_SEQ_NUM:
            size += 4;
            op += 2;
            break;
        case R_SEQ_STR:
            size += 4;
            op += 1;
            break;
        case R_SEQ_MSG:
            size += 4;
            op += 3 + op[2];
            break;
        default:
            return 1;
        }
    }
    return size ? size : 1;
}

/* Runs read ops [op, end) for the frame at `frame`. */
static int read_message(struct reader *r, const int32_t *op, const int32_t *end, size_t frame,
                        int depth) {
    if (depth > MAX_DEPTH) return RGB_FALLBACK;
    while (op < end && *op != R_END) {
        int32_t code = *op++;
        int status;
        switch (code) {
        case R_NUM:
            status = cdr_number(r, op[0], frame_slot(r, frame, op[1]));
            op += 2;
            break;
        case R_STR:
            status = cdr_string(r, frame_slot(r, frame, op[0]));
            op += 1;
            break;
        case R_ARR:
            status = cdr_numbers(r, op[0], (size_t)op[1], frame_slot(r, frame, op[2]));
            op += 3;
            break;
        case R_SEQ_NUM: {
            uint32_t count;
            status = cdr_u32(r, &count);
            if (!status) status = cdr_numbers(r, op[0], count, frame_slot(r, frame, op[1]));
            op += 2;
            break;
        }
        case R_SEQ_STR: {
            uint32_t count;
            status = cdr_u32(r, &count);
            if (status) return status;
            if (count > r->n - r->pos) return RGB_UNDECODABLE;
            struct slot *s = frame_slot(r, frame, op[0]);
            if (s != NULL) {
                s->offset = r->pos;
                s->count = count;
            }
            for (uint32_t k = 0; k < count && !status; k++) status = cdr_string(r, NULL);
            op += 1;
            break;
        }
        case R_SEQ_MSG: {
            int32_t index = op[0], nslots = op[1], body_len = op[2];
            const int32_t *body = op + 3;
            op = body + body_len;
            uint32_t count;
            status = cdr_u32(r, &count);
            if (status) return status;
            /* the elements must fit the bytes left before any slot is made for them */
            if (count > (r->n - r->pos) / min_size(body, body + body_len)) return RGB_UNDECODABLE;
            size_t first;
            status = new_frames(r, count, nslots, &first);
            if (status) return status;
            if (index >= 0) {
                struct slot *s = &r->pool[frame + (size_t)index];
                s->count = count;
                s->frame = first;
            }
            for (uint32_t k = 0; k < count && !status; k++)
                status = read_message(r, body, body + body_len, first + k * (size_t)nslots,
                                      depth + 1);
            break;
        }
        default:
            return RGB_FALLBACK;
        }
        if (status) return status;
    }
    return 0;
}

/* ---- writing protobuf ------------------------------------------------------------------- */

static int put_varint(struct rgb_out *out, uint64_t value) {
    int status = rgb_grow(out, 10);
    if (status) return status;
    do {
        uint8_t byte = value & 0x7f;
        value >>= 7;
        out->data[out->len++] = byte | (value ? 0x80 : 0);
    } while (value);
    return 0;
}

static int put_tag(struct rgb_out *out, int32_t field, int wire) {
    return put_varint(out, (uint64_t)(uint32_t)field << 3 | (uint64_t)wire);
}

static int put_length_delimited(struct rgb_out *out, int32_t field, const uint8_t *p, size_t n) {
    int status = put_tag(out, field, 2);
    if (!status) status = put_varint(out, n);
    if (!status) status = rgb_put(out, p, n);
    return status;
}

/* A ROS number as Python holds it: an integer (possibly above INT64_MAX) or a float. */
struct number {
    int is_float, is_unsigned;
    int64_t i;
    uint64_t u;
    double d;
};

static struct number ros_number(int32_t kind, uint64_t bits) {
    struct number v = {0, 0, 0, 0, 0.0};
    switch (kind) {
    case ROS_BOOL:
    case ROS_UINT8:
    case ROS_UINT16:
    case ROS_UINT32:
        v.i = (int64_t)bits;
        break;
    case ROS_INT8:
        v.i = (int8_t)(uint8_t)bits;
        break;
    case ROS_INT16:
        v.i = (int16_t)(uint16_t)bits;
        break;
    case ROS_INT32:
        v.i = (int32_t)(uint32_t)bits;
        break;
    case ROS_INT64:
        v.i = (int64_t)bits;
        break;
    case ROS_UINT64:
        v.u = bits;
        v.i = (int64_t)bits;
        v.is_unsigned = bits > INT64_MAX;
        break;
    case ROS_FLOAT: {
        uint32_t b = (uint32_t)bits;
        float f;
        memcpy(&f, &b, 4);
        v.is_float = 1;
        v.d = f;
        break;
    }
    case ROS_DOUBLE:
        v.is_float = 1;
        memcpy(&v.d, &bits, 8);
        break;
    default:
        break;
    }
    return v;
}

/* The wire value of `v` in a field of protobuf `type`, or RGB_FALLBACK where Python's
 * assignment would refuse it; *zero: proto3 leaves the field out. */
static int pb_value(int32_t type, int32_t conv, struct number v, uint64_t *wire, int *zero) {
    if (type == PB_DOUBLE || type == PB_FLOAT) {
        if (!v.is_float) return RGB_FALLBACK;
        if (type == PB_DOUBLE) {
            memcpy(wire, &v.d, 8);
        } else {
            float f = (float)v.d;
            uint32_t b;
            memcpy(&b, &f, 4);
            *wire = b;
        }
        *zero = *wire == 0;
        return 0;
    }
    if (v.is_float) return RGB_FALLBACK;
    int64_t i = v.i;
    int ok = 1;
    switch (type) {
    case PB_INT32:
    case PB_SFIXED32:
    case PB_SINT32:
    case PB_ENUM:
        if (conv == CONV_WRAP) i = (int32_t)(uint32_t)(v.is_unsigned ? v.u : (uint64_t)v.i);
        else ok = !v.is_unsigned && i >= INT32_MIN && i <= INT32_MAX;
        if (type == PB_SINT32) *wire = (uint32_t)(((uint32_t)i << 1) ^ (uint32_t)(i >> 31));
        else if (type == PB_SFIXED32) *wire = (uint32_t)i;
        else *wire = (uint64_t)i; /* negative int32: 10-byte varint, as the runtime writes */
        break;
    case PB_UINT32:
    case PB_FIXED32:
        if (conv == CONV_WRAP) {
            *wire = (uint32_t)(v.is_unsigned ? v.u : (uint64_t)v.i);
        } else {
            ok = !v.is_unsigned && i >= 0 && i <= (int64_t)UINT32_MAX;
            *wire = (uint64_t)i;
        }
        break;
    case PB_INT64:
    case PB_SFIXED64:
    case PB_SINT64:
        ok = conv == CONV_WRAP || !v.is_unsigned;
        *wire = v.is_unsigned ? v.u : (uint64_t)i;
        if (type == PB_SINT64) *wire = (*wire << 1) ^ (uint64_t)((int64_t)*wire >> 63);
        break;
    case PB_UINT64:
    case PB_FIXED64:
        ok = conv == CONV_WRAP || v.is_unsigned || i >= 0;
        *wire = v.is_unsigned ? v.u : (uint64_t)i;
        break;
    case PB_BOOL:
        ok = !v.is_unsigned && (i == 0 || i == 1);
        *wire = (uint64_t)i;
        break;
    default:
        ok = 0;
    }
    if (!ok) return RGB_FALLBACK;
    *zero = *wire == 0;
    return 0;
}

static int put_value(struct rgb_out *out, int32_t type, uint64_t wire) {
    switch (rgb_wire_of(type)) {
    case 1: {
        uint8_t b[8];
        for (int k = 0; k < 8; k++) b[k] = (uint8_t)(wire >> (8 * k));
        return rgb_put(out, b, 8);
    }
    case 5: {
        uint8_t b[4];
        for (int k = 0; k < 4; k++) b[k] = (uint8_t)(wire >> (8 * k));
        return rgb_put(out, b, 4);
    }
    default:
        return put_varint(out, wire);
    }
}

static int write_message(const struct reader *r, const int32_t *op, const int32_t *end,
                         size_t frame, struct rgb_out *out, int depth);

/* Starts a length-delimited value: room for its length, filled in by close_length. */
static int open_length(struct rgb_out *out, size_t *mark) {
    int status = rgb_grow(out, 5);
    if (status) return status;
    *mark = out->len;
    out->len += 5;
    return 0;
}

/* Writes the length of what follows `mark` as a varint there, moving the value left. */
static int close_length(struct rgb_out *out, size_t mark) {
    size_t length = out->len - mark - 5;
    if (length >= ((size_t)1 << 35)) return RGB_FALLBACK;
    uint8_t varint[5];
    size_t k = 0, rest = length;
    do {
        uint8_t byte = rest & 0x7f;
        rest >>= 7;
        varint[k++] = byte | (rest ? 0x80 : 0);
    } while (rest);
    memmove(out->data + mark + k, out->data + mark + 5, length);
    memcpy(out->data + mark, varint, k);
    out->len = mark + k + length;
    return 0;
}

/* Writes a submessage: its tag, then what `body` writes, prefixed by its length. */
static int write_submessage(const struct reader *r, int32_t field, const int32_t *body,
                            const int32_t *end, size_t frame, struct rgb_out *out, int depth) {
    size_t mark;
    int status = put_tag(out, field, 2);
    if (!status) status = open_length(out, &mark);
    if (!status) status = write_message(r, body, end, frame, out, depth + 1);
    return status ? status : close_length(out, mark);
}

static const struct slot *slot_at(const struct reader *r, size_t frame, int32_t index) {
    return &r->pool[frame + (size_t)index];
}


static int write_message(const struct reader *r, const int32_t *op, const int32_t *end,
                         size_t frame, struct rgb_out *out, int depth) {
    if (depth > MAX_DEPTH) return RGB_FALLBACK;
    while (op < end && *op != W_END) {
        int32_t code = *op++;
        int status = 0;
        switch (code) {
        case W_NUM: { /* field, pb type, ros kind, conv, slot */
            const struct slot *s = slot_at(r, frame, op[4]);
            uint64_t wire = 0;
            int zero = 0;
            status = pb_value(op[1], op[3], ros_number(op[2], s->bits), &wire, &zero);
            if (!status && !zero) {
                status = put_tag(out, op[0], rgb_wire_of(op[1]));
                if (!status) status = put_value(out, op[1], wire);
            }
            op += 5;
            break;
        }
        case W_STR:
        case W_STR_REP: { /* field, slot */
            const struct slot *s = slot_at(r, frame, op[1]);
            if (code == W_STR_REP || s->count)
                status = put_length_delimited(out, op[0], r->p + s->offset, s->count);
            op += 2;
            break;
        }
        case W_CONST_STR: /* field, text */
            if (op[1])
                status = put_length_delimited(out, op[0], (const uint8_t *)(op + 2), (size_t)op[1]);
            op += 1 + (int32_t)rgb_text_span(op[1]);
            break;
        case W_MSG: { /* field, body length, body */
            const int32_t *body = op + 2;
            status = write_submessage(r, op[0], body, body + op[1], frame, out, depth);
            op = body + op[1];
            break;
        }
        case W_SEQ_MSG: { /* field, slot, nslots, body length, body */
            const struct slot *s = slot_at(r, frame, op[1]);
            const int32_t *body = op + 4;
            for (size_t k = 0; k < s->count && !status; k++)
                status = write_submessage(r, op[0], body, body + op[3],
                                          s->frame + k * (size_t)op[2], out, depth);
            op = body + op[3];
            break;
        }
        case W_PACKED: { /* field, pb type, ros kind, slot */
            const struct slot *s = slot_at(r, frame, op[3]);
            size_t size = rgb_ros_size(op[2]);
            if (s->count) {
                size_t mark;
                status = put_tag(out, op[0], 2);
                if (!status) status = open_length(out, &mark);
                for (size_t k = 0; k < s->count && !status; k++) {
                    uint64_t wire = 0;
                    int zero;
                    uint64_t bits = load(r->p + s->offset + k * size, size);
                    status = pb_value(op[1], CONV_EXACT, ros_number(op[2], bits), &wire, &zero);
                    if (!status) status = put_value(out, op[1], wire);
                }
                if (!status) status = close_length(out, mark);
            }
            op += 4;
            break;
        }
        case W_SEQ_STR: { /* field, slot: each string of a string sequence */
            const struct slot *s = slot_at(r, frame, op[1]);
            struct reader again = {r->p, r->n, s->offset, NULL, 0, 0};
            for (size_t k = 0; k < s->count && !status; k++) {
                struct slot text;
                status = cdr_string(&again, &text);
                if (!status) status = put_length_delimited(out, op[0], r->p + text.offset, text.count);
            }
            op += 2;
            break;
        }
        default:
            return RGB_FALLBACK;
        }
        if (status) return status;
    }
    return 0;
}

enum rgb_status rgb_to_pb(const struct rgb_encoder *encoder, const uint8_t *cdr, size_t len,
                          struct rgb_out *out) {
    rgb_trim(out); /* the last message's output is no longer used */
    out->len = 0;
    out->limit = RGB_MAX_OUTPUT;
    if (len < 4 || cdr[0] != 0 || cdr[1] != 1) return RGB_FALLBACK; /* not little-endian CDR */
    struct reader r = {cdr, len, 4, NULL, 0, 0};
    size_t top;
    int status = new_frames(&r, 1, encoder->slots, &top);
    if (!status)
        status = read_message(&r, encoder->read_ops, encoder->read_ops + encoder->read_len, top, 0);
    if (!status)
        status = write_message(&r, encoder->write_ops, encoder->write_ops + encoder->write_len,
                               top, out, 0);
    free(r.pool);
    return (enum rgb_status)status;
}

/* ---- loading: every word checked once ----------------------------------------------------- */

static int kind_ok(int32_t kind) { return kind >= ROS_BOOL && kind <= ROS_DOUBLE; }

static int pb_ok(int32_t type) {
    return (type >= PB_DOUBLE && type <= PB_BOOL) || (type >= PB_UINT32 && type <= PB_SINT64);
}

/* A protobuf field number (1 to 2^29 - 1: the tag keeps 3 bits for the wire type). */
static int field_ok(int32_t field) { return field >= 1 && field <= (1 << 29) - 1; }


/* Checks read ops [0, n) of a frame of `nslots` slots. */
static int check_read(const int32_t *ops, size_t n, int32_t nslots, int depth) {
    size_t at = 0;
    if (depth > MAX_DEPTH) return -1;
#define SLOT_OK(s) ((s) >= -1 && (s) < nslots)
    while (at < n) {
        int32_t code = ops[at++];
        switch (code) {
        case R_END:
            return at == n ? 0 : -1;
        case R_NUM:
        case R_SEQ_NUM:
            if (rgb_room(n, at, 2) || !kind_ok(ops[at]) || !SLOT_OK(ops[at + 1])) return -1;
            at += 2;
            break;
        case R_STR:
        case R_SEQ_STR:
            if (rgb_room(n, at, 1) || !SLOT_OK(ops[at])) return -1;
            at += 1;
            break;
        case R_ARR:
            if (rgb_room(n, at, 3) || !kind_ok(ops[at]) || ops[at + 1] < 0 || ops[at + 1] > (1 << 24) ||
                !SLOT_OK(ops[at + 2]))
                return -1;
            at += 3;
            break;
        case R_SEQ_MSG:
            if (rgb_room(n, at, 3) || !SLOT_OK(ops[at]) || ops[at + 1] < 0 || ops[at + 1] > 4096 ||
                ops[at + 2] < 1 || rgb_room(n, at + 3, (size_t)ops[at + 2]) ||
                check_read(ops + at + 3, (size_t)ops[at + 2], ops[at + 1], depth + 1))
                return -1;
            at += 3 + (size_t)ops[at + 2];
            break;
        default:
            return -1;
        }
    }
#undef SLOT_OK
    return -1;
}

/* Checks write ops [0, n) against the read ops of their frame: each slot they use must be
 * one the read ops fill, with the right kind of content. `kinds[s]` is the read op code that
 * fills slot s (0: none), `frames[s]` the body of a message sequence. */
struct frame_info {
    int32_t nslots;
    int32_t *codes;       /* per slot: the R_* op that fills it, 0 none */
    int32_t *kinds;       /* per slot: its ROS kind (numbers) */
    const int32_t **body; /* per slot: read body of a message sequence */
    size_t *body_len;
    int32_t *body_slots;
};

static void frame_free(struct frame_info *f) {
    free(f->codes);
    free(f->kinds);
    free(f->body);
    free(f->body_len);
    free(f->body_slots);
}

static int frame_of(const int32_t *ops, size_t n, int32_t nslots, struct frame_info *f) {
    size_t count = nslots > 0 ? (size_t)nslots : 1;
    f->nslots = nslots;
    f->codes = calloc(count, sizeof *f->codes);
    f->kinds = calloc(count, sizeof *f->kinds);
    f->body = calloc(count, sizeof *f->body);
    f->body_len = calloc(count, sizeof *f->body_len);
    f->body_slots = calloc(count, sizeof *f->body_slots);
    if (!f->codes || !f->kinds || !f->body || !f->body_len || !f->body_slots) return -1;
    size_t at = 0;
    while (at < n && ops[at] != R_END) {
        int32_t code = ops[at++];
        int32_t s = -1;
        switch (code) {
        case R_NUM:
        case R_SEQ_NUM:
            s = ops[at + 1];
            if (s >= 0) f->kinds[s] = ops[at];
            at += 2;
            break;
        case R_STR:
        case R_SEQ_STR:
            s = ops[at];
            at += 1;
            break;
        case R_ARR:
            s = ops[at + 2];
            if (s >= 0) f->kinds[s] = ops[at];
            at += 3;
            break;
        case R_SEQ_MSG:
            s = ops[at];
            if (s >= 0) {
                f->body[s] = ops + at + 3;
                f->body_len[s] = (size_t)ops[at + 2];
                f->body_slots[s] = ops[at + 1];
            }
            at += 3 + (size_t)ops[at + 2];
            break;
        default:
            return -1;
        }
        if (s >= 0) {
            if (f->codes[s]) return -1; /* one op per slot */
            f->codes[s] = code;
        }
    }
    return 0;
}

static int check_write(const int32_t *ops, size_t n, const struct frame_info *f, int depth) {
    size_t at = 0;
    if (depth > MAX_DEPTH) return -1;
#define FILLED(s, code) ((s) >= 0 && (s) < f->nslots && f->codes[s] == (code))
    while (at < n) {
        int32_t code = ops[at++];
        switch (code) {
        case W_END:
            return at == n ? 0 : -1;
        case W_NUM:
            if (rgb_room(n, at, 5) || !field_ok(ops[at]) || !pb_ok(ops[at + 1]) ||
                !kind_ok(ops[at + 2]) ||
                (ops[at + 3] != CONV_EXACT && ops[at + 3] != CONV_WRAP) ||
                !FILLED(ops[at + 4], R_NUM) || f->kinds[ops[at + 4]] != ops[at + 2])
                return -1;
            at += 5;
            break;
        case W_STR:
        case W_STR_REP:
            if (rgb_room(n, at, 2) || !field_ok(ops[at]) || !FILLED(ops[at + 1], R_STR)) return -1;
            at += 2;
            break;
        case W_CONST_STR:
            if (rgb_room(n, at, 2) || !field_ok(ops[at]) || ops[at + 1] < 0 ||
                rgb_room(n, at + 1, rgb_text_span(ops[at + 1])))
                return -1;
            at += 1 + rgb_text_span(ops[at + 1]);
            break;
        case W_MSG:
            if (rgb_room(n, at, 2) || !field_ok(ops[at]) || ops[at + 1] < 1 ||
                rgb_room(n, at + 2, (size_t)ops[at + 1]) ||
                check_write(ops + at + 2, (size_t)ops[at + 1], f, depth + 1))
                return -1;
            at += 2 + (size_t)ops[at + 1];
            break;
        case W_SEQ_MSG: {
            if (rgb_room(n, at, 4) || !field_ok(ops[at]) || !FILLED(ops[at + 1], R_SEQ_MSG) ||
                ops[at + 2] != f->body_slots[ops[at + 1]] || ops[at + 3] < 1 ||
                rgb_room(n, at + 4, (size_t)ops[at + 3]))
                return -1;
            struct frame_info element = {0};
            int32_t s = ops[at + 1];
            int bad = frame_of(f->body[s], f->body_len[s], f->body_slots[s], &element) ||
                      check_write(ops + at + 4, (size_t)ops[at + 3], &element, depth + 1);
            frame_free(&element);
            if (bad) return -1;
            at += 4 + (size_t)ops[at + 3];
            break;
        }
        case W_PACKED:
            if (rgb_room(n, at, 4) || !field_ok(ops[at]) || !pb_ok(ops[at + 1]) ||
                !kind_ok(ops[at + 2]) ||
                !(FILLED(ops[at + 3], R_ARR) || FILLED(ops[at + 3], R_SEQ_NUM)) ||
                f->kinds[ops[at + 3]] != ops[at + 2])
                return -1;
            at += 4;
            break;
        case W_SEQ_STR:
            if (rgb_room(n, at, 2) || !field_ok(ops[at]) || !FILLED(ops[at + 1], R_SEQ_STR)) return -1;
            at += 2;
            break;
        default:
            return -1;
        }
    }
#undef FILLED
    return -1;
}

int rgb_encoder_load(struct rgb_encoder *encoder, const int32_t *words, size_t len,
                     const char **why) {
    /* words: top-level slots, read length, read ops, write ops */
    if (len < 2 || words[0] < 0 || words[0] > 4096 || words[1] < 1 ||
        (size_t)words[1] > len - 2) {
        *why = "encoder: bad header";
        return -1;
    }
    const int32_t *read = words + 2, *write = words + 2 + words[1];
    size_t read_len = (size_t)words[1], write_len = len - 2 - read_len;
    if (check_read(read, read_len, words[0], 0)) {
        *why = "encoder: a read op is not well-formed";
        return -1;
    }
    struct frame_info top = {0};
    int bad = frame_of(read, read_len, words[0], &top) || check_write(write, write_len, &top, 0);
    frame_free(&top);
    if (bad) {
        *why = "encoder: a write op is not well-formed";
        return -1;
    }
    encoder->read_ops = read;
    encoder->read_len = read_len;
    encoder->write_ops = write;
    encoder->write_len = write_len;
    encoder->slots = words[0];
    return 0;
}
