/* Loading a transcoder program (transcode.h rgb_load; the words: docs/native.md §2-§3): every
 * word is checked once, so that a damaged program is refused, never run; and what the ops of a
 * body write at the least, which bounds a sequence before it is written. */
#include "transcode_ops.h"


/* The fewest bytes the ops of a body (checked by check_ops) write for one element, whatever
 * its values: a CDR string or sequence writes at least its 4-byte length, a number or a fixed
 * list its size; alignment is not counted. A sequence of `count` elements thus writes at least
 * `count` times this, which lets OP_SEQ_MSG see at once that it would pass the output bound
 * (a Pose_V of 4 M empty poses wrote 128 MiB of transforms, 0.9 s, before giving up). */
size_t rgb_least_bytes(const int32_t *op, const int32_t *end) {
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
