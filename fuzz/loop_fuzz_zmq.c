/* The fake ZeroMQ SUB socket and rcl publisher of fuzz/loop_fuzz.c's Pump (loop_fuzz_pump.c):
 * the frames of the input's messages, one ZeroMQ message each (an exact copy, so that ASan sees
 * a read past it), and copies of what the pump publishes. */
#include "loop_fuzz.h"

struct fake_msg { /* inside a zmq_msg */
    uint8_t *data;
    size_t size;
    int more;
};
_Static_assert(sizeof(struct fake_msg) <= sizeof(zmq_msg), "fits in a zmq_msg");

struct message messages[MAX_MESSAGES];
int nmessages, next_read, next_frame;
int breaking, monitor_events, publish_fails;
long live; /* ZeroMQ messages received and not closed */

static struct fake_msg *fake(zmq_msg *msg) { return (struct fake_msg *)msg->bytes; }

static int f_msg_init(zmq_msg *msg) {
    memset(msg, 0, sizeof *msg);
    return 0;
}

static int f_msg_recv(zmq_msg *msg, void *socket, int flags) {
    (void)socket;
    if (next_frame == 0 && breaking) {
        breaking = 0;
        errno = ENOTSOCK;
        return -1;
    }
    if (next_read >= nmessages) {
        CHECK(next_frame == 0 && flags == 1); /* only a first frame is read without waiting */
        errno = EAGAIN;
        return -1;
    }
    struct message *m = &messages[next_read];
    const struct frame *f = &m->frames[next_frame];
    struct fake_msg *out = fake(msg);
    CHECK(out->data == NULL);
    out->data = malloc(f->size ? f->size : 1); /* exactly its size: ASan sees reads past it */
    CHECK(out->data != NULL);
    memcpy(out->data, f->data, f->size);
    out->size = f->size;
    out->more = ++next_frame < m->n;
    if (!out->more) {
        next_frame = 0;
        next_read++;
    }
    live++;
    return (int)f->size;
}

static int f_msg_close(zmq_msg *msg) {
    struct fake_msg *m = fake(msg);
    if (m->data != NULL) {
        free(m->data);
        live--;
    }
    memset(msg, 0, sizeof *msg);
    return 0;
}

static void *f_msg_data(zmq_msg *msg) { return fake(msg)->data; }
static size_t f_msg_size(const zmq_msg *msg) { return ((const struct fake_msg *)msg->bytes)->size; }
static int f_msg_more(const zmq_msg *msg) { return ((const struct fake_msg *)msg->bytes)->more; }

static int f_getsockopt(void *socket, int option, void *value, size_t *length) {
    (void)socket;
    CHECK(option == 15 && *length == sizeof(int)); /* ZMQ_EVENTS of the monitor, only */
    *(int *)value = monitor_events;
    return 0;
}

struct frame published[MAX_MESSAGES];
int npublished;

static int f_publish(const void *publisher, const void *message, void *allocation) {
    (void)publisher;
    (void)allocation;
    const rcl_bytes *m = message;
    CHECK(m->buffer_length <= m->buffer_capacity && npublished < MAX_MESSAGES);
    if (publish_fails) return 1;
    uint8_t *copy = malloc(m->buffer_length ? m->buffer_length : 1);
    CHECK(copy != NULL);
    memcpy(copy, m->buffer, m->buffer_length);
    published[npublished++] = (struct frame){copy, m->buffer_length};
    return 0;
}

static void f_reset_error(void) {}

PyObject *fake_zmq_functions(void) {
    static const struct zmq_foreign fakes = {
        .msg_init = f_msg_init, .msg_recv = f_msg_recv, .msg_close = f_msg_close,
        .msg_data = f_msg_data, .msg_size = f_msg_size, .msg_more = f_msg_more,
        .getsockopt = f_getsockopt, .publish = f_publish, .reset_error = f_reset_error,
    };
    return function_addresses(rgb_pump_functions, &fakes);
}
