/* The native transcoder, ROS -> Gazebo (encode.h; the words: docs/native.md §6).
 *
 * Every CDR byte is untrusted: each read is checked against the end of the message before it
 * is made, counts are checked against the bytes that remain before anything is sized from
 * them, and the slots and the output grow only with data that is there (with hard caps). What
 * the Python path might read otherwise (another encapsulation, a string without its NUL or
 * with one inside, text that is not UTF-8, a bool that is neither 0 nor 1, a number out of the
 * protobuf field's range) is left to it (RGB_FALLBACK). A sequence's count is checked against
 * the fewest bytes its elements take before any slot is made for them. */
#include "encode_ops.h"

#include <stdlib.h>
#include <string.h>

/* ---- reading CDR -------------------------------------------------------------------------- */

static int cdr_align(struct reader *r, size_t size) {
    size_t pad = rgb_pad(r->pos - 4, size);
    if (r->n - r->pos < pad) return RGB_UNDECODABLE;
    r->pos += pad;
    return 0;
}

static int cdr_number(struct reader *r, int32_t kind, struct slot *s) {
    size_t size = rgb_ros_size(kind);
    int status = cdr_align(r, size);
    if (status) return status;
    if (r->n - r->pos < size) return RGB_UNDECODABLE;
    uint64_t bits = rgb_le(r->p + r->pos, size);
    if (kind == ROS_BOOLEAN && bits > 1) return RGB_FALLBACK;
    if (s != NULL) s->bits = bits;
    r->pos += size;
    return 0;
}

/* A length or a count. */
static int cdr_u32(struct reader *r, uint32_t *value) {
    struct slot read = {0, 0, 0, 0};
    int status = cdr_number(r, ROS_UINT32, &read);
    *value = (uint32_t)read.bits;
    return status;
}

/* A string: its bytes without the NUL, as Python reads them. */
int enc_cdr_string(struct reader *r, struct slot *s) {
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

/* `count` numbers of `kind` (aligned to their size when there are some). */
static int cdr_numbers(struct reader *r, int32_t kind, size_t count, struct slot *s) {
    size_t size = rgb_ros_size(kind);
    if (count) {
        int status = cdr_align(r, size);
        if (status) return status;
    }
    if (count > (r->n - r->pos) / size) return RGB_UNDECODABLE;
    if (kind == ROS_BOOLEAN)
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
    if (rgb_reserve(&r->pool, &r->cap, need, sizeof *r->pool, 64)) return RGB_FALLBACK;
    /* nothing to clear for frames without slots (the pool may still be NULL then) */
    if (need > r->used) memset(r->pool + r->used, 0, (need - r->used) * sizeof *r->pool);
    *first = r->used;
    r->used = need;
    return 0;
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
            status = enc_cdr_string(r, frame_slot(r, frame, op[0]));
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
            for (uint32_t k = 0; k < count && !status; k++) status = enc_cdr_string(r, NULL);
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
            if (count > (r->n - r->pos) / enc_min_size(body, body + body_len)) return RGB_UNDECODABLE;
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
        status = enc_write_message(&r, encoder->write_ops, encoder->write_ops + encoder->write_len,
                               top, out, 0);
    free(r.pool);
    return (enum rgb_status)status;
}
