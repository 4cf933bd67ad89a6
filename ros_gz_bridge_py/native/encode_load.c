/* Loading an encoder (encode.h rgb_encoder_load; the words: docs/native.md §6): every word is
 * checked once, and each slot a write op reads must be one its frame's read ops fill, with the
 * right kind of content, so that a damaged encoder is refused, never run. */
#include "encode_ops.h"

#include <stdlib.h>
#include <string.h>

/* Each read op's operands (wire.h rgb_operands; S: its slot), by op code. */
static const char *const READ_LAYOUTS[R_COUNT] = {
    [R_NUM] = "kS",     [R_STR] = "S",     [R_ARR] = "kNS",
    [R_SEQ_NUM] = "kS", [R_SEQ_STR] = "S", [R_SEQ_MSG] = "SmB",
};
/* Each write op's operands; their slots (w) are checked against the frame's read ops. */
static const char *const WRITE_LAYOUTS[W_COUNT] = {
    [W_NUM] = "Fskcw", [W_STR] = "Fw",       [W_STR_REP] = "Fw",  [W_CONST_STR] = "FT",
    [W_MSG] = "FB",    [W_SEQ_MSG] = "FwwB", [W_PACKED] = "Fskw", [W_SEQ_STR] = "Fw",
};
#define READ_LAYOUT(code) rgb_layout(READ_LAYOUTS, R_COUNT, code)
#define WRITE_LAYOUT(code) rgb_layout(WRITE_LAYOUTS, W_COUNT, code)

/* The fewest bytes a message read by ops [op, end) takes on the wire (alignment aside): a
 * lower bound that keeps a count from sizing more slots than the bytes can hold. */
size_t enc_min_size(const int32_t *op, const int32_t *end) {
    size_t size = 0, n = (size_t)(end - op), at = 0, w[RGB_MAX_OPERANDS];
    while (at < n && op[at] != R_END) {
        int32_t code = op[at++];
        const char *layout = READ_LAYOUT(code);
        if (layout == NULL || rgb_operands(op, n, &at, layout, INT32_MAX, w)) return 1;
        switch (code) {
        case R_NUM:
            size += rgb_ros_size(op[w[0]]);
            break;
        case R_STR:
            size += 5; /* the length and the NUL */
            break;
        case R_ARR:
            size += rgb_ros_size(op[w[0]]) * (size_t)op[w[1]];
            break;
        default: /* a sequence's length */
            size += 4;
        }
    }
    return size ? size : 1;
}

/* What the read ops of a frame put in each of its slots, which its write ops are checked
 * against: each slot they use must be one the read ops fill, with the right kind of content. */
struct frame_info {
    int32_t nslots;
    struct filled {
        int32_t code;         /* the R_* op that fills it, 0 none */
        int32_t kind;         /* its ROS kind (numbers) */
        const int32_t *body;  /* a message sequence's read body, its length and slots */
        size_t body_len;
        int32_t body_slots;
    } *slots;                 /* calloc'd: the caller frees it */
};

static int frame_of(const int32_t *ops, size_t n, int32_t nslots, struct frame_info *f) {
    f->nslots = nslots;
    f->slots = calloc(nslots > 0 ? (size_t)nslots : 1, sizeof *f->slots);
    if (f->slots == NULL) return -1;
    size_t at = 0, w[RGB_MAX_OPERANDS];
    while (at < n && ops[at] != R_END) {
        int32_t code = ops[at++];
        const char *layout = READ_LAYOUT(code);
        if (layout == NULL || rgb_operands(ops, n, &at, layout, nslots, w)) return -1;
        int32_t s = ops[w[strchr(layout, 'S') - layout]];
        if (s < 0) continue;
        struct filled *slot = &f->slots[s];
        if (slot->code) return -1; /* one op per slot */
        slot->code = code;
        if (layout[0] == 'k') slot->kind = ops[w[0]];
        if (code == R_SEQ_MSG) {
            slot->body = ops + w[2] + 1;
            slot->body_len = (size_t)ops[w[2]];
            slot->body_slots = ops[w[1]];
        }
    }
    return 0;
}

static int check_write(const int32_t *ops, size_t n, const struct frame_info *f, int depth) {
    size_t at = 0, w[RGB_MAX_OPERANDS];
    if (depth > MAX_DEPTH) return -1;
#define FILLED(s, c) ((s) >= 0 && (s) < f->nslots && f->slots[s].code == (c))
    while (at < n) {
        int32_t code = ops[at++];
        if (code == W_END) return at == n ? 0 : -1;
        const char *layout = WRITE_LAYOUT(code);
        if (layout == NULL || rgb_operands(ops, n, &at, layout, 0, w)) return -1;
        int32_t s = ops[w[1]]; /* the slot, where it is the second operand */
        int ok = 1;
        switch (code) {
        case W_NUM: /* field, pb type, ros kind, conv, slot */
            ok = FILLED(ops[w[4]], R_NUM) && f->slots[ops[w[4]]].kind == ops[w[2]];
            break;
        case W_STR:
        case W_STR_REP:
            ok = FILLED(s, R_STR);
            break;
        case W_MSG:
            ok = !check_write(ops + w[1] + 1, (size_t)ops[w[1]], f, depth + 1);
            break;
        case W_SEQ_MSG: { /* field, slot, nslots, body */
            if (!FILLED(s, R_SEQ_MSG) || ops[w[2]] != f->slots[s].body_slots) return -1;
            const struct filled *sequence = &f->slots[s];
            struct frame_info element = {0};
            ok = !frame_of(sequence->body, sequence->body_len, sequence->body_slots, &element) &&
                 !check_write(ops + w[3] + 1, (size_t)ops[w[3]], &element, depth + 1);
            free(element.slots);
            break;
        }
        case W_PACKED: /* field, pb type, ros kind, slot */
            ok = (FILLED(ops[w[3]], R_ARR) || FILLED(ops[w[3]], R_SEQ_NUM)) &&
                 f->slots[ops[w[3]]].kind == ops[w[2]];
            break;
        case W_SEQ_STR:
            ok = FILLED(s, R_SEQ_STR);
            break;
        default: /* W_CONST_STR: its operands say it all */
            break;
        }
        if (!ok) return -1;
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
    if (rgb_check_body(read, read_len, READ_LAYOUTS, R_COUNT, words[0], 0, MAX_DEPTH)) {
        *why = "encoder: a read op is not well-formed";
        return -1;
    }
    struct frame_info top = {0};
    int bad = frame_of(read, read_len, words[0], &top) || check_write(write, write_len, &top, 0);
    free(top.slots);
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
