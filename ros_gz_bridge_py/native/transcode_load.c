/* Loading a transcoder program (transcode.h rgb_load; the words: docs/native.md §2-§3): every
 * word is checked once, so that a damaged program is refused, never run; and what the ops of a
 * body write at the least, which bounds a sequence before it is written. */
#include "transcode_ops.h"

const char *const rgb_op_layouts[OP_COUNT] = {
    [OP_NUM] = "Pfskc",      [OP_CONST] = "kww",        [OP_STR] = "Pf",
    [OP_CONST_STR] = "T",    [OP_HEADER_STR] = "PcTT",  [OP_FIXED_LIST] = "Pfskn",
    [OP_SEQ_MSG] = "PfB",    [OP_COLUMN] = "PfPfsk",    [OP_COLUMN_STR] = "PfPf",
    [OP_CLOCK] = "Pc",       [OP_WALL_STAMP] = "",      [OP_CONST_BLOCK] = "aT",
};

/* The fewest bytes the ops of a body (checked by rgb_load) write for one element, whatever
 * its values: a CDR string or sequence writes at least its 4-byte length, a number or a fixed
 * list its size; alignment is not counted. A sequence of `count` elements thus writes at least
 * `count` times this, which lets OP_SEQ_MSG see at once that it would pass the output bound
 * (a Pose_V of 4 M empty poses wrote 128 MiB of transforms, 0.9 s, before giving up). */
size_t rgb_least_bytes(const int32_t *op, const int32_t *end) {
    size_t least = 0, n = (size_t)(end - op), at = 0, w[RGB_MAX_OPERANDS];
    while (at < n && op[at] != OP_END) {
        int32_t code = op[at++];
        const char *layout = rgb_layout(rgb_op_layouts, OP_COUNT, code);
        if (layout == NULL || rgb_operands(op, n, &at, layout, 0, w))
            return least; /* rgb_load admits no such op */
        switch (code) {
        case OP_NUM:
            least += rgb_ros_size(op[w[3]]);
            break;
        case OP_CONST:
            least += rgb_ros_size(op[w[0]]);
            break;
        case OP_FIXED_LIST:
            least += (size_t)op[w[4]] * rgb_ros_size(op[w[3]]);
            break;
        case OP_WALL_STAMP:
            least += 8;
            break;
        case OP_CONST_BLOCK:
            least += (size_t)op[w[1]];
            break;
        default: /* a string's or a sequence's length, a clock's int32 or uint32 */
            least += 4;
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

int rgb_load(struct rgb_program *program, const int32_t *schema, size_t schema_len,
             const int32_t *ops, size_t ops_len, const char **why) {
    if (check_schema(schema, schema_len, why)) return -1;
    if (rgb_check_body(ops, ops_len, rgb_op_layouts, OP_COUNT, 0, 0, MAX_DEPTH)) {
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
