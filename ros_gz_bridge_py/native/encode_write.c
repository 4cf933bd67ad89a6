/* Writing the protobuf payload of an encoder (encode_ops.h; docs/native.md §6): the write ops
 * in field-number order, from the slots the read ops filled, as the Python runtime serializes
 * the message after the converter ran; a number the Python path would refuse or write another
 * way (out of the field's range) is left to it (RGB_FALLBACK). */
#include "encode_ops.h"

#include <math.h>
#include <string.h>

/* `value` as a varint at `b` (10 bytes at most); its length. */
static size_t varint(uint64_t value, uint8_t b[10]) {
    size_t k = 0;
    do {
        uint8_t byte = value & 0x7f;
        value >>= 7;
        b[k++] = byte | (value ? 0x80 : 0);
    } while (value);
    return k;
}

static int put_varint(struct rgb_out *out, uint64_t value) {
    uint8_t b[10];
    return rgb_put(out, b, varint(value, b));
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

/* A ROS number of `kind` from its bits, as Python holds it. */
static struct rgb_number ros_number(int32_t kind, uint64_t bits) {
    struct rgb_ros_type type = rgb_ros_type(kind);
    if (kind == ROS_FLOAT || kind == ROS_DOUBLE) return rgb_float_bits(bits, type.size);
    if (type.min == 0) return rgb_u64(bits); /* unsigned (a kind not ROS's: none loads) */
    uint64_t sign = (uint64_t)1 << (8 * type.size - 1); /* of the `size` bytes read */
    return (struct rgb_number){0, 0, (int64_t)((bits ^ sign) - sign), 0, 0.0};
}

/* The wire value of `v` in a field of protobuf `type`, or RGB_FALLBACK where Python's
 * assignment would refuse it; *zero: proto3 leaves the field out. */
static int pb_value(int32_t type, int32_t conv, struct rgb_number v, uint64_t *wire, int *zero) {
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
    /* The field's range as a ROS integer of the same width and sign: what an exact assignment
     * takes, and what CONV_WRAP narrows to (C++'s static_cast); a bool is always exact. */
    int32_t as = ROS_UINT64;
    if (type == PB_INT32 || type == PB_SFIXED32 || type == PB_SINT32 || type == PB_ENUM)
        as = ROS_INT32;
    else if (type == PB_UINT32 || type == PB_FIXED32) as = ROS_UINT32;
    else if (type == PB_INT64 || type == PB_SFIXED64 || type == PB_SINT64) as = ROS_INT64;
    else if (type == PB_BOOL) as = ROS_BOOLEAN;
    else if (type != PB_UINT64 && type != PB_FIXED64) return RGB_FALLBACK;
    struct rgb_ros_type range = rgb_ros_type(as);
    uint64_t bits = v.is_unsigned ? v.u : (uint64_t)v.i;
    if (conv != CONV_WRAP || as == ROS_BOOLEAN) {
        if (!rgb_in_range(v, range.min, range.max)) return RGB_FALLBACK;
    } else if (range.size == 4) {
        bits = (uint64_t)ros_number(as, bits & UINT32_MAX).i; /* sign-extended for int32 */
    }
    if (type == PB_SINT32) /* zigzag: 0, -1, 1, -2 ... as 0, 1, 2, 3 ... */
        bits = (uint32_t)(((uint32_t)bits << 1) ^ (uint32_t)((int64_t)bits >> 31));
    else if (type == PB_SINT64)
        bits = (bits << 1) ^ (uint64_t)((int64_t)bits >> 63);
    else if (type == PB_SFIXED32)
        bits = (uint32_t)bits;
    *wire = bits; /* a negative int32 as a varint: 10 bytes, as the runtime writes */
    *zero = *wire == 0;
    return 0;
}

static int put_value(struct rgb_out *out, int32_t type, uint64_t wire) {
    switch (rgb_wire_of(type)) {
    case WIRE_I64:
        return rgb_put_le(out, wire, 8);
    case WIRE_I32:
        return rgb_put_le(out, wire, 4);
    default:
        return put_varint(out, wire);
    }
}

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
    uint8_t b[10];
    size_t k = varint(length, b); /* 5 bytes at most */
    memmove(out->data + mark + k, out->data + mark + 5, length);
    memcpy(out->data + mark, b, k);
    out->len = mark + k + length;
    return 0;
}

/* Writes a submessage: its tag, then what `body` writes, prefixed by its length. */
static int write_submessage(const struct reader *r, int32_t field, const int32_t *body,
                            const int32_t *end, size_t frame, struct rgb_out *out, int depth) {
    size_t mark;
    int status = put_tag(out, field, 2);
    if (!status) status = open_length(out, &mark);
    if (!status) status = enc_write_message(r, body, end, frame, out, depth + 1);
    return status ? status : close_length(out, mark);
}

static const struct slot *slot_at(const struct reader *r, size_t frame, int32_t index) {
    return &r->pool[frame + (size_t)index];
}


int enc_write_message(const struct reader *r, const int32_t *op, const int32_t *end,
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
                    uint64_t bits = rgb_le(r->p + s->offset + k * size, size);
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
                status = enc_cdr_string(&again, &text);
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
