/* The native transcoder, ROS -> Gazebo: ROS CDR messages to Gazebo protobuf payloads.
 *
 * Sans-IO, as transcode.h. program.py compiles each pair's declaration into words of two
 * parts (docs/native.md §6): read ops that walk the CDR message in wire order and keep each
 * field the conversion uses in a slot, and write ops that write the protobuf message in field
 * number order from the slots. */
#ifndef RGB_ENCODE_H
#define RGB_ENCODE_H

#include <stddef.h>
#include <stdint.h>

#include "transcode.h"

/* A loaded ROS -> Gazebo program (the caller keeps the words alive). */
struct rgb_encoder {
    const int32_t *read_ops;
    size_t read_len;
    const int32_t *write_ops;
    size_t write_len;
    int32_t slots; /* slots of the top-level frame */
};

/* Checks the words (read_len, the read ops, then the write ops); 0 when they make a program,
 * else -1 with a reason in *why. */
int rgb_encoder_load(struct rgb_encoder *encoder, const int32_t *words, size_t len,
                     const char **why);

/* Encodes one CDR message (with its encapsulation header); on RGB_OK, out->data[0..out->len)
 * is the protobuf payload. RGB_UNDECODABLE: the CDR is cut short or inconsistent;
 * RGB_FALLBACK: the Python path decides. */
enum rgb_status rgb_to_pb(const struct rgb_encoder *encoder, const uint8_t *cdr, size_t len,
                          struct rgb_out *out);

#endif
