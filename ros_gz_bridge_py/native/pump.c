/* The per-message work of a native Gazebo -> ROS channel (docs/native.md §5).
 *
 * A Pump is one channel's state: its routes, its queue, its programs, its publisher. The
 * process's one loop (loop.c) runs every pump with the GIL released: it reads each message's
 * four frames from the topic's SUB socket (pump_read), keeps the newest `capacity` payloads and
 * at most `max_bytes` of them (dropping the oldest, before any work is spent on them), applies
 * max_rate, transcodes each payload with the program of its wire type and publishes it through
 * rcl on the channel's publisher (pump_deliver). No Python runs per message. What it does not
 * decide is handed back to Python, which stays the reference: frames of a (sender, type) it has
 * not been told about (Python judges them and tells it with `learn`), and payloads its program
 * does not take (Python converts them, or says why not): `take_handed` gives them to Python.
 *
 * libzmq and rcl are the libraries pyzmq and rclpy already loaded: Python passes the addresses
 * of their functions (pump.py). */
#define PY_SSIZE_T_CLEAN
#include "pump.h"

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

/* ---- the foreign functions ------------------------------------------------------------------ */

/* zmq_msg_t: 64 bytes, aligned as a pointer (zmq.h). */
typedef union {
    unsigned char bytes[64];
    void *align;
} zmq_msg;

typedef struct {
    uint8_t *buffer;
    size_t buffer_length;
    size_t buffer_capacity;
    void *allocator[5];
} rcl_serialized;

enum { ZMQ_POLLIN_ = 1, ZMQ_DONTWAIT_ = 1, ZMQ_FD_ = 14, ZMQ_EVENTS_ = 15 };
/* libzmq's errno for a terminated context (zmq.h: ZMQ_HAUSNUMERO + 53). */
#define ETERM_ (156384712 + 53)

struct foreign {
    int (*msg_init)(zmq_msg *msg);
    int (*msg_recv)(zmq_msg *msg, void *socket, int flags);
    int (*msg_close)(zmq_msg *msg);
    void *(*msg_data)(zmq_msg *msg);
    size_t (*msg_size)(const zmq_msg *msg);
    int (*msg_more)(const zmq_msg *msg);
    int (*getsockopt)(void *socket, int option, void *value, size_t *length);
    int (*publish)(const void *publisher, const rcl_serialized *message, void *allocation);
    void (*reset_error)(void);
};

/* ---- the pump --------------------------------------------------------------------------------- */

#define MAX_FRAMES 16
#define HISTORY 1024
#define MAX_ROUTES 1024
/* Routes a full table keeps: the most recently used (and those a waiting message names). */
#define KEEP_ROUTES (MAX_ROUTES / 2)
/* Bytes of a dropped payload's sender kept for the warning that names it (longer: cut). */
#define DROP_SENDER_MAX 256

/* What a (sender, type) pair of frames gets: a program, or nothing (another spelling taken). */
struct route {
    uint8_t *sender, *type;
    size_t sender_len, type_len;
    int program; /* index into programs, or -1: skip without a word */
    uint64_t used; /* the pump's `taken` when a message last took this route */
};

struct queued {
    zmq_msg payload;
    int route;
};

/* A message handed to Python: its frames (unrouted), its payload (refused), or why it is too
 * large (RGB_TOO_LARGE: no copy, Python only words the refusal). */
enum { HANDED_UNROUTED = 0, HANDED_REFUSED = 1, HANDED_TOO_LARGE = 2 };
struct handed {
    int kind;
    int route, status, nframes;
    uint8_t *data[MAX_FRAMES];
    size_t size[MAX_FRAMES];
    size_t items, least, payload_size; /* HANDED_TOO_LARGE */
};

struct window {
    uint64_t sequence;
    int64_t start, end;
};

struct PumpObject {
    PyObject_HEAD
    struct foreign f;
    void *publisher;
    uint8_t *topic;
    size_t topic_len;
    PyObject *program_objects; /* list, keeps the programs alive */
    struct rgb_program **programs;
    uint8_t **program_types;
    size_t *program_type_lens;
    int nprograms;
    struct route *routes;
    int nroutes;
    struct queued *ring;
    size_t capacity, head, count;
    size_t max_bytes, queued_bytes; /* the ring's bound in payload bytes, and what it holds */
    /* A payload larger than watch_above (SIZE_MAX: none) is told to Python (take_grown): the
     * reader lowers the socket's receive HWM for it (transport/zmq/reader.py). */
    size_t watch_above, grown;
    struct handed *handover;
    size_t nhanded, handed_cap;
    size_t handed_bytes; /* the bytes of the copies handed (a read ends past max_bytes) */
    struct rgb_out out;
    int64_t period_ns, next_ns; /* max_rate: next admission time (period 0: no limit) */
    unsigned long long received, rate_limited, published, dropped, skipped;
    unsigned long long lost; /* messages for Python that could not be copied (no memory) */
    unsigned long long taken; /* messages read from the socket, whatever became of them */
    unsigned long long bytes_read; /* their payload bytes (the loop's trim after a burst) */
    uint8_t drop_sender[DROP_SENDER_MAX]; /* the sender of the last payload dropped */
    size_t drop_sender_len;
    pthread_mutex_t lock; /* the windows and the sequence (read by is_own from any thread) */
    uint64_t sequence;
    struct window windows[HISTORY];
    const atomic_int *running; /* while attached: the loop's "running" flag (loop.c) */
};

static PyTypeObject PumpType;

static int64_t now_ns(clockid_t clock) {
    struct timespec t;
    clock_gettime(clock, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

/* ---- publication windows (the loop guard, core/loop_guard.py) ----------------------------- */

static uint64_t begin_publication(PumpObject *self) {
    pthread_mutex_lock(&self->lock);
    uint64_t sequence = ++self->sequence;
    struct window *w = &self->windows[sequence % HISTORY];
    w->sequence = sequence;
    w->start = now_ns(CLOCK_REALTIME);
    w->end = INT64_MAX;
    pthread_mutex_unlock(&self->lock);
    return sequence;
}

static void end_publication(PumpObject *self, uint64_t sequence, int ok) {
    pthread_mutex_lock(&self->lock);
    struct window *w = &self->windows[sequence % HISTORY];
    if (!ok) {
        w->sequence = 0;
        if (self->sequence == sequence) self->sequence--;
    } else if (w->sequence == sequence) {
        w->end = now_ns(CLOCK_REALTIME);
    }
    pthread_mutex_unlock(&self->lock);
}

/* ---- the loop (no GIL) ---------------------------------------------------------------------- */

static int find_route(PumpObject *self, const uint8_t *sender, size_t sender_len,
                      const uint8_t *type, size_t type_len) {
    for (int i = 0; i < self->nroutes; i++) {
        struct route *r = &self->routes[i];
        if (r->sender_len == sender_len && r->type_len == type_len &&
            !memcmp(r->sender, sender, sender_len) && !memcmp(r->type, type, type_len))
            return i;
    }
    return -1;
}

static struct handed *hand(PumpObject *self) {
    if (self->nhanded == self->handed_cap) {
        size_t cap = self->handed_cap ? self->handed_cap * 2 : 16;
        struct handed *grown = realloc(self->handover, cap * sizeof *grown);
        if (grown == NULL) return NULL;
        self->handover = grown;
        self->handed_cap = cap;
    }
    struct handed *h = &self->handover[self->nhanded++];
    memset(h, 0, sizeof *h);
    return h;
}

/* Copies `n` bytes (NULL only when memory runs out). */
static uint8_t *copy_bytes(const void *p, size_t n) {
    uint8_t *copy = malloc(n ? n : 1);
    if (copy != NULL && n) memcpy(copy, p, n);
    return copy;
}

/* Hands `n` frames to Python as copies. When memory runs out nothing is handed (an empty
 * payload would parse as a valid all-default message) and the message is counted as lost. */
static void hand_frames(PumpObject *self, int kind, int route, int status, zmq_msg *frames,
                        int n) {
    struct handed *h = hand(self);
    if (h == NULL) {
        self->lost++;
        return;
    }
    h->kind = kind;
    h->route = route;
    h->status = status;
    for (int i = 0; i < n; i++) {
        h->size[i] = self->f.msg_size(&frames[i]);
        h->data[i] = copy_bytes(self->f.msg_data(&frames[i]), h->size[i]);
        h->nframes = i + 1;
        if (h->data[i] == NULL) {
            for (int k = 0; k < i; k++) free(h->data[k]);
            self->nhanded--;
            self->lost++;
            return;
        }
    }
    for (int i = 0; i < n; i++) self->handed_bytes += h->size[i];
}

/* Hands Python the figures of a payload refused as too large (route `route`): its list's items,
 * the least bytes of one, its own size. */
static void hand_too_large(PumpObject *self, int route, size_t payload_size) {
    struct handed *h = hand(self);
    if (h == NULL) {
        self->lost++;
        return;
    }
    h->kind = HANDED_TOO_LARGE;
    h->route = route;
    h->status = RGB_TOO_LARGE;
    h->items = self->out.refused.items;
    h->least = self->out.refused.least;
    h->payload_size = payload_size;
}

static void drop_oldest(PumpObject *self) {
    struct queued *oldest = &self->ring[self->head];
    const struct route *r = &self->routes[oldest->route];
    self->drop_sender_len = r->sender_len < DROP_SENDER_MAX ? r->sender_len : DROP_SENDER_MAX;
    memcpy(self->drop_sender, r->sender, self->drop_sender_len);
    self->queued_bytes -= self->f.msg_size(&oldest->payload);
    self->f.msg_close(&oldest->payload);
    self->head = (self->head + 1) % self->capacity;
    self->count--;
    self->dropped++;
}

/* Queues a payload; the oldest go first, before any work on them, while the ring is full or
 * would hold more than max_bytes (one payload is always kept, as the Python path's queue). */
static void keep(PumpObject *self, zmq_msg *payload, int route) {
    size_t size = self->f.msg_size(payload);
    while (self->count && (self->count == self->capacity ||
                           self->queued_bytes + size > self->max_bytes))
        drop_oldest(self);
    struct queued *slot = &self->ring[(self->head + self->count) % self->capacity];
    memcpy(&slot->payload, payload, sizeof *payload);
    slot->route = route;
    self->count++;
    self->queued_bytes += size;
}

/* Reads one message: 1 when one was read, 0 when none was waiting, -1 when the socket cannot
 * be read (its context terminated, or it is closed). The socket's own ZMQ_EVENTS is never
 * asked: a SUB socket answers it by prefetching a message (see loop.c). */
static int read_message(PumpObject *self, void *sock) {
    zmq_msg frames[MAX_FRAMES];
    int n = 0, more = 1, extra = 0;
    while (more) {
        zmq_msg scratch, *frame = n < MAX_FRAMES ? &frames[n] : &scratch;
        self->f.msg_init(frame);
        if (self->f.msg_recv(frame, sock, n ? 0 : ZMQ_DONTWAIT_) < 0) {
            int error = errno;
            self->f.msg_close(frame);
            if (n == 0) return error == EAGAIN || error == EINTR ? 0 : -1;
            break; /* a later frame cannot fail once the first is read (ZeroMQ is atomic) */
        }
        more = self->f.msg_more(frame);
        if (frame == &scratch) {
            self->f.msg_close(&scratch); /* beyond the frames kept: Python sees too many */
            extra = 1;
        } else {
            n++;
        }
    }
    self->taken++;
    if (n > 2) {
        size_t size = self->f.msg_size(&frames[2]);
        self->bytes_read += size;
        if (size > self->watch_above && size > self->grown) self->grown = size;
    }
    int route = -1;
    if (n == 4 && !extra && self->f.msg_size(&frames[0]) == self->topic_len &&
        !memcmp(self->f.msg_data(&frames[0]), self->topic, self->topic_len)) {
        route = find_route(self, self->f.msg_data(&frames[1]), self->f.msg_size(&frames[1]),
                           self->f.msg_data(&frames[3]), self->f.msg_size(&frames[3]));
        if (route >= 0) self->routes[route].used = self->taken;
    }
    if (route >= 0 && self->routes[route].program >= 0) {
        keep(self, &frames[2], route);
        self->f.msg_close(&frames[0]);
        self->f.msg_close(&frames[1]);
        self->f.msg_close(&frames[3]);
        return 1;
    }
    if (route >= 0) /* a spelling already taken from this publisher: not ours */
        self->skipped++;
    else
        hand_frames(self, HANDED_UNROUTED, -1, 0, frames, n);
    for (int i = 0; i < n; i++) self->f.msg_close(&frames[i]);
    return 1;
}

static int admit(PumpObject *self) {
    if (self->period_ns <= 0) return 1;
    int64_t now = now_ns(CLOCK_MONOTONIC);
    if (self->next_ns != INT64_MIN && now < self->next_ns) return 0;
    /* on the schedule, or a fresh start after a pause (core/rate_limit.py) */
    int on_time = self->next_ns != INT64_MIN && now - self->next_ns < self->period_ns;
    self->next_ns = on_time ? self->next_ns + self->period_ns : now + self->period_ns;
    return 1;
}

static void deliver(PumpObject *self, struct queued *q) {
    self->received++;
    if (!admit(self)) {
        self->rate_limited++;
        return;
    }
    int program = self->routes[q->route].program;
    const uint8_t *data = self->f.msg_data(&q->payload);
    size_t size = self->f.msg_size(&q->payload);
    enum rgb_status status = rgb_to_cdr(self->programs[program], data, size, &self->out);
    if (status == RGB_OK) {
        rcl_serialized message = {self->out.data, self->out.len, self->out.cap, {0}};
        uint64_t sequence = begin_publication(self);
        int ret = self->f.publish(self->publisher, &message, NULL);
        end_publication(self, sequence, ret == 0);
        rgb_out_trim(&self->out); /* a large message's buffer goes back at once */
        if (ret == 0) {
            self->published++;
            return;
        }
        self->f.reset_error();
        status = RGB_FALLBACK; /* Python publishes it, or says why it cannot */
    }
    if (status == RGB_TOO_LARGE)
        hand_too_large(self, q->route, size);
    else
        hand_frames(self, HANDED_REFUSED, q->route, (int)status, &q->payload, 1);
}

/* ---- what the loop calls (loop.c; no GIL) ------------------------------------------------ */

int pump_zmq_fd(PumpObject *self, void *sock) {
    int fd = -1;
    size_t size = sizeof fd;
    return self->f.getsockopt(sock, ZMQ_FD_, &fd, &size) == 0 ? fd : -1;
}

int pump_monitor_ready(PumpObject *self, void *monitor) {
    int events = 0;
    size_t size = sizeof events;
    return self->f.getsockopt(monitor, ZMQ_EVENTS_, &events, &size) == 0 &&
           (events & ZMQ_POLLIN_);
}

/* Reads up to `budget` messages: 1 once none waits, 0 when more may wait, -1 when the socket
 * cannot be read. The read also ends early (0) once a payload outgrew the watched size, so the
 * reader replaces the socket before a budget more of them arrive, and once the copies handed to
 * Python hold max_bytes, so that Python learns their route before more are copied: either
 * used to wait for a whole budget of 32 MB messages (2 GB, /clock starved meanwhile). */
int pump_read(PumpObject *self, void *sock, int budget) {
    for (int i = 0; i < budget; i++) {
        int read = read_message(self, sock);
        if (read <= 0) return read < 0 ? -1 : 1;
        if (self->grown || self->handed_bytes >= self->max_bytes) return 0;
    }
    return 0;
}

void pump_deliver(PumpObject *self, int budget, int64_t slice_end) {
    for (int i = 0; i < budget && self->count; i++) {
        struct queued *q = &self->ring[self->head];
        self->head = (self->head + 1) % self->capacity;
        self->count--;
        self->queued_bytes -= self->f.msg_size(&q->payload);
        deliver(self, q);
        self->f.msg_close(&q->payload);
        if (now_ns(CLOCK_MONOTONIC) >= slice_end) break;
    }
}

size_t pump_queued(const PumpObject *self) { return self->count; }

size_t pump_handed(const PumpObject *self) { return self->nhanded + (self->grown != 0); }

unsigned long long pump_taken(const PumpObject *self) { return self->taken; }

PumpObject *native_pump_of(PyObject *object) {
    if (!PyObject_TypeCheck(object, &PumpType)) return NULL;
    PumpObject *pump = (PumpObject *)object;
    return pump->topic == NULL ? NULL : pump;
}

int pump_attach(PumpObject *self, const atomic_int *running) {
    if (self->running != NULL) return -1;
    self->running = running;
    return 0;
}

void pump_detach(PumpObject *self) { self->running = NULL; }

/* ---- Python methods -------------------------------------------------------------------------- */

static void clear_handover(PumpObject *self) {
    for (size_t i = 0; i < self->nhanded; i++)
        for (int k = 0; k < self->handover[i].nframes; k++) free(self->handover[i].data[k]);
    self->nhanded = 0;
    self->handed_bytes = 0;
}

static void free_route(struct route *r) {
    free(r->sender);
    free(r->type);
}

static void clear_routes(PumpObject *self) {
    for (int i = 0; i < self->nroutes; i++) free_route(&self->routes[i]);
    free(self->routes);
    self->routes = NULL;
    self->nroutes = 0;
}

static void clear_ring(PumpObject *self) {
    while (self->count) {
        self->f.msg_close(&self->ring[self->head].payload);
        self->head = (self->head + 1) % self->capacity;
        self->count--;
    }
    self->queued_bytes = 0;
}

static int newest_first(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? 1 : x > y ? -1 : 0;
}

/* Makes room in a full route table: the KEEP_ROUTES most recently used routes stay, and so do
 * those a queued or handed message names (under a new index); the others are forgotten, and
 * Python judges their next message again. A sender that changes its sender frame every message
 * thus costs its own messages a trip through Python, never the routes of the publishers that
 * keep sending, nor anyone's queue. */
static void evict_routes(PumpObject *self) {
    size_t n = (size_t)self->nroutes;
    int *renumber = malloc(n * sizeof *renumber);
    char *keep = calloc(n, 1);
    uint64_t *uses = malloc(n * sizeof *uses);
    if (renumber == NULL || keep == NULL || uses == NULL) { /* no memory: forget them all */
        free(renumber);
        free(keep);
        free(uses);
        self->dropped += self->count + self->nhanded;
        clear_ring(self);
        clear_handover(self);
        clear_routes(self);
        return;
    }
    for (size_t i = 0; i < n; i++) uses[i] = self->routes[i].used;
    qsort(uses, n, sizeof *uses, newest_first);
    uint64_t oldest_kept = uses[KEEP_ROUTES - 1];
    for (size_t i = 0; i < n; i++) keep[i] = self->routes[i].used > oldest_kept;
    for (size_t i = 0; i < self->count; i++)
        keep[self->ring[(self->head + i) % self->capacity].route] = 1;
    for (size_t i = 0; i < self->nhanded; i++)
        if (self->handover[i].kind == 1) keep[self->handover[i].route] = 1;
    int kept = 0;
    for (size_t i = 0; i < n; i++) {
        if (keep[i]) {
            renumber[i] = kept;
            self->routes[kept++] = self->routes[i];
        } else {
            free_route(&self->routes[i]);
        }
    }
    for (size_t i = 0; i < self->count; i++) {
        struct queued *q = &self->ring[(self->head + i) % self->capacity];
        q->route = renumber[q->route];
    }
    for (size_t i = 0; i < self->nhanded; i++)
        if (self->handover[i].kind == 1)
            self->handover[i].route = renumber[self->handover[i].route];
    self->nroutes = kept;
    free(renumber);
    free(keep);
    free(uses);
}

static void pump_dealloc(PumpObject *self) {
    if (self->ring != NULL) clear_ring(self);
    free(self->ring);
    clear_handover(self);
    free(self->handover);
    clear_routes(self);
    for (int i = 0; i < self->nprograms; i++) free(self->program_types[i]);
    free(self->program_types);
    free(self->program_type_lens);
    free(self->programs);
    free(self->topic);
    Py_XDECREF(self->program_objects);
    rgb_out_free(&self->out);
    pthread_mutex_destroy(&self->lock);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *pump_new(PyTypeObject *type, PyObject *args, PyObject *kwds) {
    PumpObject *self = (PumpObject *)type->tp_alloc(type, 0);
    if (self != NULL) pthread_mutex_init(&self->lock, NULL);
    (void)args;
    (void)kwds;
    return (PyObject *)self;
}

/* 0, or -1 with a Python error when the pump was never initialised (Pump.__new__ alone) or
 * (`idle`) while the loop runs it. */
static int usable(PumpObject *self, int idle) {
    if (self->topic == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "the Pump is not initialised");
        return -1;
    }
    if (idle && self->running != NULL && atomic_load(self->running)) {
        PyErr_SetString(PyExc_RuntimeError, "the Pump's loop is running it");
        return -1;
    }
    return 0;
}

/* Pump(topic, functions, publisher, programs, capacity, max_rate, max_bytes)
 * functions: 9 addresses (zmq_msg_init, zmq_msg_recv, zmq_msg_close, zmq_msg_data,
 * zmq_msg_size, zmq_msg_more, zmq_getsockopt, rcl_publish_serialized_message,
 * rcutils_reset_error); programs: {wire type (bytes): Program}. */
static int pump_init(PumpObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {"topic", "functions", "publisher", "programs", "capacity",
                               "max_rate", "max_bytes", NULL};
    Py_buffer topic;
    PyObject *functions, *programs;
    unsigned long long publisher;
    Py_ssize_t capacity, max_bytes;
    double max_rate;
    if (self->topic != NULL || self->ring != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "a Pump is initialised once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "y*OKO!ndn", keywords, &topic, &functions,
                                     &publisher, &PyDict_Type, &programs, &capacity, &max_rate,
                                     &max_bytes))
        return -1;
    int result = -1;
    void *addresses[9];
    if (native_addresses(functions, addresses, sizeof addresses / sizeof *addresses) < 0)
        goto done;
    if (publisher == 0 || capacity < 1 || capacity > (1 << 24) || !(max_rate >= 0) ||
        max_bytes < 1) {
        PyErr_SetString(PyExc_ValueError,
                        "publisher, capacity, max_rate or max_bytes out of range");
        goto done;
    }
    memcpy(&self->f.msg_init, &addresses[0], sizeof(void *));
    memcpy(&self->f.msg_recv, &addresses[1], sizeof(void *));
    memcpy(&self->f.msg_close, &addresses[2], sizeof(void *));
    memcpy(&self->f.msg_data, &addresses[3], sizeof(void *));
    memcpy(&self->f.msg_size, &addresses[4], sizeof(void *));
    memcpy(&self->f.msg_more, &addresses[5], sizeof(void *));
    memcpy(&self->f.getsockopt, &addresses[6], sizeof(void *));
    memcpy(&self->f.publish, &addresses[7], sizeof(void *));
    memcpy(&self->f.reset_error, &addresses[8], sizeof(void *));
    self->publisher = (void *)(uintptr_t)publisher;
    Py_ssize_t n = PyDict_Size(programs);
    self->programs = calloc((size_t)n + 1, sizeof *self->programs);
    self->program_types = calloc((size_t)n + 1, sizeof *self->program_types);
    self->program_type_lens = calloc((size_t)n + 1, sizeof *self->program_type_lens);
    self->ring = calloc((size_t)capacity, sizeof *self->ring);
    if (!self->programs || !self->program_types || !self->program_type_lens || !self->ring) {
        PyErr_NoMemory();
        goto done;
    }
    self->capacity = (size_t)capacity;
    self->max_bytes = (size_t)max_bytes;
    self->watch_above = SIZE_MAX;
    self->program_objects = PyList_New(0);
    if (self->program_objects == NULL) goto done;
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    while (PyDict_Next(programs, &pos, &key, &value)) {
        struct rgb_program *program = native_program_of(value);
        if (!PyBytes_Check(key) || program == NULL) {
            PyErr_SetString(PyExc_TypeError, "programs: {bytes: Program}");
            goto done;
        }
        if (PyList_Append(self->program_objects, value) < 0) goto done;
        int i = self->nprograms++;
        self->programs[i] = program;
        self->program_type_lens[i] = (size_t)PyBytes_GET_SIZE(key);
        self->program_types[i] = copy_bytes(PyBytes_AS_STRING(key), self->program_type_lens[i]);
        if (self->program_types[i] == NULL) {
            PyErr_NoMemory();
            goto done;
        }
    }
    self->period_ns = max_rate > 0 ? (int64_t)(1e9 / max_rate) : 0;
    self->next_ns = INT64_MIN;
    /* set last: a Pump with a topic is whole (native_pump_of, usable) */
    self->topic = copy_bytes(topic.buf, (size_t)topic.len);
    if (self->topic == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    self->topic_len = (size_t)topic.len;
    result = 0;
done:
    PyBuffer_Release(&topic);
    return result;
}

/* learn(sender, msg_type, take): what messages of (sender, type) get from now on. */
static PyObject *pump_learn(PumpObject *self, PyObject *args) {
    Py_buffer sender, type;
    int take;
    if (usable(self, 1) < 0) return NULL;
    if (!PyArg_ParseTuple(args, "y*y*p", &sender, &type, &take)) return NULL;
    PyObject *result = NULL;
    int program = -1;
    for (int i = 0; take && i < self->nprograms; i++)
        if (self->program_type_lens[i] == (size_t)type.len &&
            !memcmp(self->program_types[i], type.buf, (size_t)type.len))
            program = i;
    if (take && program < 0) { /* taken, but no program: stays with Python */
        result = Py_NewRef(Py_False);
        goto done;
    }
    if (find_route(self, sender.buf, (size_t)sender.len, type.buf, (size_t)type.len) < 0) {
        if (self->nroutes >= MAX_ROUTES) evict_routes(self);
        if (self->nroutes >= MAX_ROUTES) { /* every route is named by a waiting message */
            result = Py_NewRef(Py_False);
            goto done;
        }
        struct route *grown = realloc(self->routes, (size_t)(self->nroutes + 1) * sizeof *grown);
        if (grown == NULL) {
            PyErr_NoMemory();
            goto done;
        }
        self->routes = grown;
        struct route *r = &self->routes[self->nroutes];
        r->sender = copy_bytes(sender.buf, (size_t)sender.len);
        r->type = copy_bytes(type.buf, (size_t)type.len);
        if (r->sender == NULL || r->type == NULL) {
            free_route(r);
            PyErr_NoMemory();
            goto done;
        }
        r->sender_len = (size_t)sender.len;
        r->type_len = (size_t)type.len;
        r->program = program;
        r->used = self->taken; /* as new as the message that made Python learn it */
        self->nroutes++;
    }
    result = Py_NewRef(Py_True);
done:
    PyBuffer_Release(&sender);
    PyBuffer_Release(&type);
    return result;
}

static PyObject *pump_forget(PumpObject *self, PyObject *unused) {
    (void)unused;
    if (usable(self, 0) < 0) return NULL;
    if (self->running != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "forget while a loop runs the pump");
        return NULL;
    }
    clear_routes(self);
    clear_ring(self);
    clear_handover(self);
    Py_RETURN_NONE;
}

static Py_ssize_t size_ssize(size_t n) {
    return n > (size_t)PY_SSIZE_T_MAX ? PY_SSIZE_T_MAX : (Py_ssize_t)n;
}

/* take_handed() -> [(0, frames)] unrouted, [(1, sender, type, payload, status)] refused,
 * [(2, sender, type, items, least, payload_size)] too large: what the loop left to Python
 * since the last call. A message whose Python copy cannot be made (no memory) is counted as
 * lost, as in hand_frames, and the others are still handed; when the list itself cannot
 * grow, what it would have held is lost and MemoryError raised. */
static PyObject *pump_take_handed(PumpObject *self, PyObject *unused) {
    (void)unused;
    if (usable(self, 1) < 0) return NULL;
    PyObject *handed = PyList_New(0);
    if (handed == NULL) self->lost += self->nhanded;
    for (size_t i = 0; handed != NULL && i < self->nhanded; i++) {
        struct handed *h = &self->handover[i];
        PyObject *item;
        if (h->kind == HANDED_UNROUTED) {
            PyObject *frames = PyList_New(0);
            for (int k = 0; frames != NULL && k < h->nframes; k++) {
                PyObject *frame = PyBytes_FromStringAndSize((char *)h->data[k], (Py_ssize_t)h->size[k]);
                if (frame == NULL || PyList_Append(frames, frame) < 0) Py_CLEAR(frames);
                Py_XDECREF(frame);
            }
            item = frames == NULL ? NULL : Py_BuildValue("(iN)", 0, frames);
        } else if (h->kind == HANDED_TOO_LARGE) {
            struct route *r = &self->routes[h->route];
            item = Py_BuildValue("(iy#y#nnn)", HANDED_TOO_LARGE, (char *)r->sender,
                                 (Py_ssize_t)r->sender_len, (char *)r->type,
                                 (Py_ssize_t)r->type_len, size_ssize(h->items),
                                 size_ssize(h->least), size_ssize(h->payload_size));
        } else {
            struct route *r = &self->routes[h->route];
            item = Py_BuildValue("(iy#y#y#i)", HANDED_REFUSED, (char *)r->sender, (Py_ssize_t)r->sender_len,
                                 (char *)r->type, (Py_ssize_t)r->type_len, (char *)h->data[0],
                                 (Py_ssize_t)h->size[0], h->status);
        }
        if (item == NULL) {
            PyErr_Clear();
            self->lost++;
            continue;
        }
        if (PyList_Append(handed, item) < 0) {
            self->lost += self->nhanded - i + (size_t)PyList_GET_SIZE(handed);
            Py_CLEAR(handed);
        }
        Py_DECREF(item);
    }
    clear_handover(self);
    return handed;
}

/* take_grown() -> the largest payload above the watched size since the last call (0: none) */
static PyObject *pump_take_grown(PumpObject *self, PyObject *unused) {
    (void)unused;
    if (usable(self, 1) < 0) return NULL;
    size_t grown = self->grown;
    self->grown = 0;
    return PyLong_FromSize_t(grown);
}

/* watch(size): payloads larger than `size` are told (take_grown); a negative size: none. */
static PyObject *pump_watch(PumpObject *self, PyObject *arg) {
    if (usable(self, 1) < 0) return NULL;
    long long size = PyLong_AsLongLong(arg);
    if (size == -1 && PyErr_Occurred()) return NULL;
    self->watch_above = size < 0 ? SIZE_MAX : (size_t)size;
    Py_RETURN_NONE;
}

static PyObject *pump_counts(PumpObject *self, PyObject *unused) {
    (void)unused;
    return Py_BuildValue("(KKKKKK)", self->received, self->rate_limited, self->published,
                         self->dropped, self->skipped, self->lost);
}

/* traffic() -> (payload bytes read so far, sender of the last payload dropped: b"" if none) */
static PyObject *pump_traffic(PumpObject *self, PyObject *unused) {
    (void)unused;
    return Py_BuildValue("(Ky#)", self->bytes_read, (char *)self->drop_sender,
                         (Py_ssize_t)self->drop_sender_len);
}

static PyObject *pump_begin_publication(PumpObject *self, PyObject *unused) {
    (void)unused;
    return PyLong_FromUnsignedLongLong(begin_publication(self));
}

static PyObject *pump_end_publication(PumpObject *self, PyObject *args) {
    unsigned long long sequence;
    int ok;
    if (!PyArg_ParseTuple(args, "Kp", &sequence, &ok)) return NULL;
    end_publication(self, sequence, ok);
    Py_RETURN_NONE;
}

static PyObject *pump_is_own(PumpObject *self, PyObject *args) {
    unsigned long long sequence;
    long long stamp;
    if (!PyArg_ParseTuple(args, "KL", &sequence, &stamp)) return NULL;
    int own;
    pthread_mutex_lock(&self->lock);
    struct window *w = &self->windows[sequence % HISTORY];
    own = sequence != 0 && w->sequence == sequence && w->start <= stamp && stamp <= w->end;
    pthread_mutex_unlock(&self->lock);
    return PyBool_FromLong(own);
}

static PyMethodDef pump_methods[] = {
    {"learn", (PyCFunction)pump_learn, METH_VARARGS,
     "learn(sender, msg_type, take) -> bool: route messages of (sender, type) natively (take) "
     "or skip them; False where no program takes msg_type"},
    {"forget", (PyCFunction)pump_forget, METH_NOARGS, "forget routes and queued messages"},
    {"take_handed", (PyCFunction)pump_take_handed, METH_NOARGS,
     "take_handed() -> [(0, frames)] unrouted, [(1, sender, type, payload, status)] refused, "
     "[(2, sender, type, items, least, payload_size)] too large"},
    {"take_grown", (PyCFunction)pump_take_grown, METH_NOARGS,
     "take_grown() -> the largest payload above the watched size since the last call (0: none)"},
    {"watch", (PyCFunction)pump_watch, METH_O,
     "watch(size): payloads larger than size are told by take_grown (negative: none)"},
    {"counts", (PyCFunction)pump_counts, METH_NOARGS,
     "(received, rate_limited, published, dropped, skipped, lost) so far"},
    {"traffic", (PyCFunction)pump_traffic, METH_NOARGS,
     "(payload bytes read so far, sender of the last payload dropped)"},
    {"begin_publication", (PyCFunction)pump_begin_publication, METH_NOARGS,
     "a publication made from Python on the same publisher: its sequence number"},
    {"end_publication", (PyCFunction)pump_end_publication, METH_VARARGS,
     "end_publication(sequence, ok)"},
    {"is_own", (PyCFunction)pump_is_own, METH_VARARGS,
     "is_own(sequence, source_timestamp_ns) -> bool: a sample this publisher wrote"},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject PumpType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.Pump",
    .tp_basicsize = sizeof(PumpObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The per-message work of one Gazebo -> ROS channel (docs/native.md §5).",
    .tp_new = pump_new,
    .tp_init = (initproc)pump_init,
    .tp_dealloc = (destructor)pump_dealloc,
    .tp_methods = pump_methods,
};

int pump_register(PyObject *module) {
    if (PyType_Ready(&PumpType) < 0) return -1;
    Py_INCREF(&PumpType);
    if (PyModule_AddObject(module, "Pump", (PyObject *)&PumpType) < 0) {
        Py_DECREF(&PumpType);
        return -1;
    }
    return 0;
}
