/* Reading a protobuf payload for the transcoder (transcode_ops.h; docs/native.md §4).
 *
 * Every payload byte is untrusted: each read is checked against the end of its view before it
 * is made, and lengths are compared with what remains before they are used. A payload is first
 * validated against the whole schema, as the Python protobuf runtime does when it parses
 * (UTF-8 of every string field, every nested message), so that what the transcoder accepts
 * the Python path accepts too; anything this code is not sure about is left to Python
 * (RGB_FALLBACK). Each message the ops read is indexed once (struct node), which every op
 * reads from, so that the work is linear in the payload: the payload and its singular
 * submessages by the validating scan itself, a sequence's elements and the rest when reached. */
#include "transcode_ops.h"

#include <stdlib.h>
#include <string.h>

/* ---- the schema ---------------------------------------------------------------------------- */

/* The words of message type `msg`: its field count, then 4 words a field. */
static const int32_t *message_words(const struct rgb_program *pr, int32_t msg) {
    return pr->schema + pr->schema[1 + msg];
}

/* The index among message `m`'s fields of the one numbered `number`, or -1 when unknown. */
static int field_index(const int32_t *m, uint32_t number) {
    /* the descriptors of Gazebo's messages mostly list field n n-th */
    uint32_t guess = number - 1; /* wraps for 0, which no field has */
    if (guess < (uint32_t)m[0] && (uint32_t)m[1 + 4 * guess] == number) return (int)guess;
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

static struct node *node_at(struct ctx *c, size_t offset) {
    return (struct node *)((uint8_t *)c->out->scratch + offset);
}

/* Reserves an index for a message of type `msg` on the scratch stack, its slots empty. */
static int push_node(struct ctx *c, int32_t msg, size_t *offset) {
    const int32_t *m = message_words(c->pr, msg);
    size_t size = sizeof(struct node) + (size_t)m[0] * sizeof(struct slot);
    if (size > MAX_SCRATCH - c->top) return RGB_FALLBACK;
    size_t need = c->top + size;
    if (rgb_reserve(&c->out->scratch, &c->out->scratch_cap, need, 1, 4096)) return RGB_FALLBACK;
    *offset = c->top;
    c->top = need;
    struct node *n = node_at(c, *offset);
    n->msg = msg;
    for (int32_t i = 0; i < m[0]; i++)
        n->slots[i] = (struct slot){0, 0, 0, {0, 0, 0, {NULL, 0}}, NO_NODE};
    return 0;
}

/* Reads the field at *pos of a message of schema words `m` into `f`, with its index among
 * m's fields in *k (-1: unknown); a known one is recorded in the index `node` (NO_NODE: none). */
static int read_known(struct ctx *c, struct view v, size_t *pos, const int32_t *m, size_t node,
                      struct field *f, int *k) {
    size_t start = *pos;
    int status = read_field(c, v, pos, f);
    if (status) return status;
    *k = field_index(m, f->number);
    if (*k >= 0 && node != NO_NODE) {
        struct slot *s = &node_at(c, node)->slots[*k];
        if (s->count++ == 0) s->first = start;
        s->end = *pos;
        s->last = *f;
    }
    return 0;
}

int pb_validate(struct ctx *c, struct view v, int32_t msg, int depth, size_t *node) {
    if (depth > MAX_DEPTH) return RGB_FALLBACK;
    const int32_t *m = message_words(c->pr, msg);
    int status = node != NULL ? push_node(c, msg, node) : 0;
    if (status) return status;
    /* Singular submessages seen, to leave merged duplicates to Python (bit per field). */
    uint64_t seen = 0;
    size_t pos = 0;
    while (pos < v.n) {
        struct field f;
        int index;
        status = read_known(c, v, &pos, m, node != NULL ? *node : NO_NODE, &f, &index);
        if (status) return status;
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
            /* a singular one of an indexed message is indexed in the same scan, while the
             * index is small (each sequence element is indexed when its turn comes) */
            int eager = node != NULL && !repeated && c->top <= EAGER_SCRATCH;
            size_t child = NO_NODE;
            status = pb_validate(c, f.payload, sf[3], depth + 1, eager ? &child : NULL);
            if (status) return status;
            if (eager) node_at(c, *node)->slots[index].child = child;
        } else if (type == PB_GROUP) {
            return RGB_FALLBACK;
        }
    }
    return 0;
}

/* ---- finding values (in a validated message) --------------------------------------------- */

/* The last occurrence of field `number` (a singular field: the one Python keeps), or the first
 * (`first`: a repeated field's first element), found by scanning `v`; found 0 when absent. */
int pb_find(struct ctx *c, struct view v, uint32_t number, int first, struct field *out,
            int *found) {
    size_t pos = 0;
    *found = 0;
    while (pos < v.n && !(first && *found)) {
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

int pb_index_message(struct ctx *c, struct view v, int32_t msg, size_t *offset) {
    int status = push_node(c, msg, offset);
    if (status) return status;
    const int32_t *m = message_words(c->pr, msg);
    size_t pos = 0;
    while (pos < v.n && !status) {
        struct field f;
        int k;
        status = read_known(c, v, &pos, m, *offset, &f, &k);
    }
    return status;
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

/* The last occurrence of field `number` of `a`, from slot `k` of its index (-1: scanned). */
static int last_in(struct ctx *c, struct at a, int k, uint32_t number, struct field *out,
                   int *found) {
    if (k < 0) return pb_find(c, a.v, number, 0, out, found);
    const struct slot *s = &node_at(c, a.node)->slots[k];
    *found = s->count > 0;
    if (*found) *out = s->last;
    return 0;
}

int pb_last_of(struct ctx *c, struct at a, uint32_t number, struct field *out, int *found) {
    return last_in(c, a, slot_of(c, a, number, NULL), number, out, found);
}

/* The submessage reached through `steps` (an empty view where one is absent), indexed where
 * the schema gives its type (each submessage once, however many ops read it). */
int pb_descend(struct ctx *c, struct at a, const int32_t *steps, int32_t nsteps,
                   struct at *out) {
    for (int32_t i = 0; i < nsteps; i++) {
        const int32_t *sf = NULL;
        int k = slot_of(c, a, (uint32_t)steps[i], &sf);
        struct field f;
        int found, status = last_in(c, a, k, (uint32_t)steps[i], &f, &found);
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
            status = pb_index_message(c, f.payload, sf[3], &child);
            if (status) return status;
            node_at(c, a.node)->slots[k].child = child; /* the scratch may have moved */
        }
        a = (struct at){f.payload, child};
    }
    *out = a;
    return 0;
}

struct rgb_number pb_decode_scalar(int32_t type, uint64_t raw) {
    struct rgb_number val = {0, 0, 0, 0, 0.0};
    if (type == PB_SINT32) raw = (uint32_t)raw;
    if (type == PB_SINT32 || type == PB_SINT64) raw = (raw >> 1) ^ (~(raw & 1) + 1); /* zigzag */
    switch (type) {
    case PB_DOUBLE:
    case PB_FLOAT:
        return rgb_float_bits(raw, type == PB_DOUBLE ? 8 : 4);
    case PB_UINT64:
    case PB_FIXED64:
        return rgb_u64(raw);
    case PB_INT64:
    case PB_SFIXED64:
    case PB_SINT64:
        val.i = (int64_t)raw;
        break;
    case PB_INT32:
    case PB_ENUM:
    case PB_SFIXED32:
    case PB_SINT32:
        val.i = (int32_t)(uint32_t)raw;
        break;
    case PB_UINT32:
    case PB_FIXED32:
        val.i = (uint32_t)raw;
        break;
    case PB_BOOL:
        val.i = raw != 0;
        break;
    default:
        break;
    }
    return val;
}

uint64_t pb_raw_of(const struct field *f) {
    if (f->wire == WIRE_VARINT) return f->varint;
    return rgb_le(f->payload.p, f->wire == WIRE_I64 ? 8 : 4);
}

int pb_scalar(struct ctx *c, struct at v, uint32_t number, int32_t type, struct rgb_number *val) {
    struct field f;
    int found, status = pb_last_of(c, v, number, &f, &found);
    if (status) return status;
    if (found && f.wire != rgb_wire_of(type)) return RGB_FALLBACK;
    *val = pb_decode_scalar(type, found ? pb_raw_of(&f) : 0);
    return 0;
}

int pb_for_each(struct ctx *c, struct at v, uint32_t number, element_fn each, void *arg) {
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

static int count_field(void *ctx, const struct field *f) {
    (void)f;
    (*(size_t *)ctx)++;
    return 0;
}

int pb_count_of(struct ctx *c, struct at v, uint32_t number, size_t *count) {
    int k = slot_of(c, v, number, NULL);
    if (k >= 0) {
        *count = node_at(c, v.node)->slots[k].count;
        return 0;
    }
    *count = 0;
    return pb_for_each(c, v, number, count_field, count);
}

int32_t pb_element_type(struct ctx *c, struct at v, uint32_t number) {
    const int32_t *sf = NULL;
    if (slot_of(c, v, number, &sf) < 0 || sf[1] != PB_MESSAGE) return -1;
    return sf[3];
}
