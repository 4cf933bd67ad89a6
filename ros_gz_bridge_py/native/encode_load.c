/* Loading an encoder (encode.h rgb_encoder_load; the words: docs/native.md §6): every word is
 * checked once, and each slot a write op reads must be one its frame's read ops fill, with the
 * right kind of content, so that a damaged encoder is refused, never run. */
#include "encode_ops.h"

#include <stdlib.h>

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
