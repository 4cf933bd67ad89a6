/* The native transcoder: Gazebo protobuf payloads to ROS CDR, driven by a program.
 *
 * Sans-IO: no Python, no sockets, no allocation outside the output buffer (and its scratch,
 * the index of the messages read). The Python side (program.py) compiles each pair's
 * declaration into two arrays of int32 words, a schema of the Gazebo message types
 * (docs/native.md §2) and a program of ROS fields in wire order (§3); rgb_load checks both
 * once, and rgb_to_cdr runs them on untrusted payloads. */
#ifndef RGB_TRANSCODE_H
#define RGB_TRANSCODE_H

#include <stddef.h>
#include <stdint.h>

/* What rgb_to_cdr made of a payload (docs/native.md §4). */
enum rgb_status {
    RGB_OK = 0,          /* the CDR bytes are in the output buffer */
    RGB_UNDECODABLE = 1, /* not a valid protobuf encoding of the message type */
    RGB_CONVERSION = 2,  /* a valid message the converter refuses */
    RGB_FALLBACK = 3,    /* valid or not: the Python path decides */
    RGB_TOO_LARGE = 4,   /* valid, but a list in it would make a ROS message over the output
                            bound however Python counts it: refused, not built (out->refused) */
};

/* A loaded program: the caller's words (kept alive by the caller) after rgb_load checked
 * them. */
struct rgb_program {
    const int32_t *schema;
    size_t schema_len;
    const int32_t *ops;
    size_t ops_len;
    int32_t root; /* schema index of the Gazebo message type */
};

/* A growable output buffer (all zero before first use), with the transcoder's scratch. */
struct rgb_out {
    uint8_t *data;
    size_t len;
    size_t cap;
    size_t limit;       /* most bytes this call may write (0: RGB_MAX_OUTPUT); set per call */
    void *scratch;      /* rgb_to_cdr's index of the payload's messages, reused between calls */
    size_t scratch_cap; /* its bytes */
    size_t refuse_above; /* a list whose least bytes pass this is RGB_TOO_LARGE; set per call */
    struct {
        size_t items, least; /* RGB_TOO_LARGE: the list's items, the least CDR bytes of one */
    } refused;
};

/* Checks the words; 0 when they make a program, else -1 with a reason in *why. */
int rgb_load(struct rgb_program *program, const int32_t *schema, size_t schema_len,
             const int32_t *ops, size_t ops_len, const char **why);

/* Transcodes one payload; on RGB_OK, out->data[0..out->len) is the CDR message with its
 * encapsulation header. out is reused between calls (out->len is reset first). Where `steps`
 * is not NULL, *steps says how many protobuf fields it read, the work that bounds its time: a
 * few times the fields of the payload, whatever the program (the tests check it). */
enum rgb_status rgb_to_cdr(const struct rgb_program *program, const uint8_t *payload,
                           size_t payload_len, struct rgb_out *out, size_t *steps);

/* Frees the output buffer and the scratch. */
void rgb_out_free(struct rgb_out *out);

#endif
