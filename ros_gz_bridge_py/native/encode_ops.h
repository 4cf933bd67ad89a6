/* What the ROS -> Gazebo transcoder's files share (private: encode.h is its interface): the
 * slots the read ops fill (the ops of an encoder, docs/native.md §6, are numbered in codes.h).
 * encode.c reads the CDR message into slots, encode_write.c writes the protobuf payload from
 * them, encode_load.c checks an encoder's words once. */
#ifndef RGB_ENCODE_OPS_H
#define RGB_ENCODE_OPS_H

#include "encode.h"
#include "wire.h"

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

/* Reads a CDR string at r->pos into `s` (its bytes without the NUL; s may be NULL). */
int enc_cdr_string(struct reader *r, struct slot *s);
/* The fewest bytes a message read by ops [op, end) takes (encode_load.c). */
size_t enc_min_size(const int32_t *op, const int32_t *end);
/* Runs write ops [op, end) for the frame at `frame` into `out`. */
int enc_write_message(const struct reader *r, const int32_t *op, const int32_t *end,
                      size_t frame, struct rgb_out *out, int depth);

#endif
