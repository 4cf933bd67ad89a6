/* The per-message loop of a native ROS -> Gazebo channel (docs/native.md §7).
 *
 * Run by the channel's own thread with the GIL released: rcl tells of new messages through the
 * subscription's on-new-message callback (an eventfd), each message is taken serialized from
 * the rclpy subscription's rcl handle, skipped when one of the bridge's own publishers on the
 * topic wrote it (by publisher GID, as the C++ bridge does), passed through max_rate, encoded
 * (encode.c) in each spelling Gazebo subscribers take and sent as the four data frames on the
 * channel's own ZeroMQ PUB socket. No Python runs per message; what an encoder leaves to Python
 * is handed back, and Python converts it as without the native path. rcl, rmw, rcutils and
 * libzmq functions come from the libraries rclpy and pyzmq loaded (ros_pump.py). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <poll.h>
#include <pthread.h>
#include <stdint.h>
#include <string.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include "encode.h"
#include "pump.h"

/* rcutils_allocator_t, rcl_serialized_message_t, rmw_gid_t and rmw_message_info_t as Jazzy's
 * headers lay them out. */
typedef struct {
    void *(*allocate)(size_t size, void *state);
    void (*deallocate)(void *pointer, void *state);
    void *(*reallocate)(void *pointer, size_t size, void *state);
    void *(*zero_allocate)(size_t count, size_t size, void *state);
    void *state;
} rcu_allocator;

typedef struct {
    uint8_t *buffer;
    size_t buffer_length;
    size_t buffer_capacity;
    rcu_allocator allocator;
} rcl_bytes;

#define GID_SIZE 16
typedef struct {
    const char *implementation_identifier;
    uint8_t data[GID_SIZE];
} rmw_gid;

typedef struct {
    int64_t source_timestamp;
    int64_t received_timestamp;
    uint64_t publication_sequence_number;
    uint64_t reception_sequence_number;
    rmw_gid publisher_gid;
    _Bool from_intra_process;
} rmw_info;

typedef void (*event_callback)(const void *user_data, size_t number_of_events);

struct ros_foreign {
    int (*take)(const void *subscription, rcl_bytes *message, rmw_info *info, void *allocation);
    int (*set_callback)(const void *subscription, event_callback callback, const void *user_data);
    void (*reset_error)(void);
    rcu_allocator (*default_allocator)(void);
    void *(*publisher_rmw_handle)(const void *publisher);
    int (*gid_for_publisher)(const void *rmw_publisher, rmw_gid *gid);
    int (*send)(void *socket, const void *buffer, size_t length, int flags);
};

enum { RCL_TAKE_FAILED = 401, ZMQ_SNDMORE_ = 2, ZMQ_DONTWAIT_ = 1 };
#define BATCH 256
#define MAX_SPELLINGS 4
#define MAX_IGNORED 16
#define INITIAL_CAPACITY 4096

struct spelling {
    uint8_t *type, *topic, *sender;
    size_t type_len, topic_len, sender_len;
    struct rgb_encoder *encoder;
    int active;
};

typedef struct {
    PyObject_HEAD
    struct ros_foreign f;
    void *subscription;
    void *sock;
    int event_fd;
    int callback_set;
    int running;
    PyObject *encoders; /* list: keeps the Encoder objects alive */
    struct spelling spellings[MAX_SPELLINGS];
    int nspellings;
    rcl_bytes message;
    struct rgb_out out[MAX_SPELLINGS];
    uint8_t ignored[MAX_IGNORED][GID_SIZE];
    int nignored;
    int64_t period_ns, next_ns;
    unsigned long long received, own_skipped, rate_limited, published, take_errors;
    uint8_t **refused;
    size_t *refused_len;
    size_t nrefused, refused_cap;
} RosPumpObject;

static int64_t monotonic_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

/* rcl's on-new-message callback, on a middleware thread: wake the loop. */
static void on_new_message(const void *user_data, size_t number_of_events) {
    const RosPumpObject *self = user_data;
    uint64_t n = number_of_events ? number_of_events : 1;
    ssize_t written = write(self->event_fd, &n, sizeof n);
    (void)written; /* a full counter still wakes the loop */
}

static int admit(RosPumpObject *self) {
    if (self->period_ns <= 0) return 1;
    int64_t now = monotonic_ns();
    if (self->next_ns != INT64_MIN && now < self->next_ns) return 0;
    int on_time = self->next_ns != INT64_MIN && now - self->next_ns < self->period_ns;
    self->next_ns = on_time ? self->next_ns + self->period_ns : now + self->period_ns;
    return 1;
}

static int is_ignored(const RosPumpObject *self, const rmw_gid *gid) {
    for (int i = 0; i < self->nignored; i++)
        if (!memcmp(self->ignored[i], gid->data, GID_SIZE)) return 1;
    return 0;
}

static void refuse(RosPumpObject *self, const uint8_t *cdr, size_t len) {
    if (self->nrefused == self->refused_cap) {
        size_t cap = self->refused_cap ? self->refused_cap * 2 : 16;
        uint8_t **grown = realloc(self->refused, cap * sizeof *grown);
        size_t *grown_len = realloc(self->refused_len, cap * sizeof *grown_len);
        if (grown != NULL) self->refused = grown;
        if (grown_len != NULL) self->refused_len = grown_len;
        if (grown == NULL || grown_len == NULL) return;
        self->refused_cap = cap;
    }
    uint8_t *copy = malloc(len ? len : 1);
    if (copy == NULL) return;
    if (len) memcpy(copy, cdr, len);
    self->refused[self->nrefused] = copy;
    self->refused_len[self->nrefused++] = len;
}

static void send_frames(RosPumpObject *self, const struct spelling *s, const struct rgb_out *out) {
    void *sock = self->sock;
    const char *empty = "";
    self->f.send(sock, s->topic, s->topic_len, ZMQ_SNDMORE_ | ZMQ_DONTWAIT_);
    self->f.send(sock, s->sender, s->sender_len, ZMQ_SNDMORE_ | ZMQ_DONTWAIT_);
    self->f.send(sock, out->len ? (const void *)out->data : empty, out->len,
                 ZMQ_SNDMORE_ | ZMQ_DONTWAIT_);
    self->f.send(sock, s->type, s->type_len, ZMQ_DONTWAIT_);
}

/* One taken message: encoded in the configured spelling (the first) and in each spelling a
 * subscriber takes, then sent in the latter; or handed to Python. */
static void deliver(RosPumpObject *self, const uint8_t *cdr, size_t len) {
    int encoded[MAX_SPELLINGS] = {0};
    for (int i = 0; i < self->nspellings; i++) {
        struct spelling *s = &self->spellings[i];
        if (i > 0 && !s->active) continue;
        int same = -1; /* an earlier spelling encoded by the same encoder */
        for (int k = 0; k < i && same < 0; k++)
            if (encoded[k] == 1 && self->spellings[k].encoder == s->encoder) same = k;
        if (same >= 0) {
            encoded[i] = 2 + same; /* its output serves this spelling too */
            continue;
        }
        if (rgb_to_pb(s->encoder, cdr, len, &self->out[i]) != RGB_OK) {
            refuse(self, cdr, len);
            return;
        }
        encoded[i] = 1;
    }
    for (int i = 0; i < self->nspellings; i++) {
        struct spelling *s = &self->spellings[i];
        if (!s->active) continue;
        send_frames(self, s, &self->out[encoded[i] >= 2 ? encoded[i] - 2 : i]);
    }
    self->published++;
}

/* Takes what waits (at most BATCH messages); how many were taken. */
static int drain(RosPumpObject *self) {
    int taken = 0;
    while (taken < BATCH) {
        rmw_info info;
        memset(&info, 0, sizeof info);
        self->message.buffer_length = 0;
        int ret = self->f.take(self->subscription, &self->message, &info, NULL);
        if (ret == RCL_TAKE_FAILED) break;
        if (ret != 0) {
            self->f.reset_error();
            self->take_errors++;
            break;
        }
        taken++;
        self->received++;
        if (is_ignored(self, &info.publisher_gid)) {
            self->own_skipped++;
            continue;
        }
        if (!admit(self)) {
            self->rate_limited++;
            continue;
        }
        deliver(self, self->message.buffer, self->message.buffer_length);
    }
    return taken;
}

enum { EVENT_WAKE = 1, EVENT_HANDED = 4 };

static int ros_loop(RosPumpObject *self, int wake_fd, long timeout_ms) {
    int64_t deadline = monotonic_ns() + (int64_t)timeout_ms * 1000000LL;
    for (;;) {
        int taken = drain(self);
        if (self->nrefused) return EVENT_HANDED;
        int64_t left = deadline - monotonic_ns();
        if (left <= 0) return 0;
        if (taken == BATCH) continue;
        struct pollfd fds[2] = {{self->event_fd, POLLIN, 0}, {wake_fd, POLLIN, 0}};
        int ready = poll(fds, 2, (int)((left + 999999) / 1000000));
        if (ready < 0) return 0;
        if (fds[0].revents & POLLIN) {
            uint64_t count;
            ssize_t got = read(self->event_fd, &count, sizeof count);
            (void)got;
        }
        if (fds[1].revents) return EVENT_WAKE;
    }
}

/* ---- Python ------------------------------------------------------------------------------------ */

static void clear_refused(RosPumpObject *self) {
    for (size_t i = 0; i < self->nrefused; i++) free(self->refused[i]);
    self->nrefused = 0;
}

static void stop_callback(RosPumpObject *self) {
    if (self->callback_set) {
        self->f.set_callback(self->subscription, NULL, NULL);
        self->f.reset_error();
        self->callback_set = 0;
    }
}

static void ros_pump_dealloc(RosPumpObject *self) {
    stop_callback(self);
    if (self->event_fd >= 0) close(self->event_fd);
    if (self->message.buffer != NULL)
        self->message.allocator.deallocate(self->message.buffer, self->message.allocator.state);
    for (int i = 0; i < self->nspellings; i++) {
        free(self->spellings[i].type);
        free(self->spellings[i].topic);
        free(self->spellings[i].sender);
    }
    for (int i = 0; i < MAX_SPELLINGS; i++) rgb_out_free(&self->out[i]);
    clear_refused(self);
    free(self->refused);
    free(self->refused_len);
    Py_XDECREF(self->encoders);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *ros_pump_new(PyTypeObject *type, PyObject *args, PyObject *kwds) {
    RosPumpObject *self = (RosPumpObject *)type->tp_alloc(type, 0);
    if (self != NULL) self->event_fd = -1;
    (void)args;
    (void)kwds;
    return (PyObject *)self;
}

static uint8_t *copy_buffer(PyObject *bytes, size_t *len) {
    if (!PyBytes_Check(bytes)) return NULL;
    *len = (size_t)PyBytes_GET_SIZE(bytes);
    uint8_t *copy = malloc(*len ? *len : 1);
    if (copy != NULL && *len) memcpy(copy, PyBytes_AS_STRING(bytes), *len);
    return copy;
}

/* RosPump(functions, subscription, sock, spellings, max_rate)
 * functions: 7 addresses (rcl_take_serialized_message,
 * rcl_subscription_set_on_new_message_callback, rcutils_reset_error,
 * rcutils_get_default_allocator, rcl_publisher_get_rmw_handle, rmw_get_gid_for_publisher,
 * zmq_send); spellings: [(type, topic, sender, Encoder)], the configured spelling first. */
static int ros_pump_init(RosPumpObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {"functions", "subscription", "sock", "spellings", "max_rate", NULL};
    PyObject *functions, *spellings;
    unsigned long long subscription, sock;
    double max_rate;
    if (self->encoders != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "a RosPump is initialised once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "OKKO!d", keywords, &functions, &subscription,
                                     &sock, &PyList_Type, &spellings, &max_rate))
        return -1;
    void *addresses[7];
    if (native_addresses(functions, addresses, sizeof addresses / sizeof *addresses) < 0)
        return -1;
    Py_ssize_t n = PyList_GET_SIZE(spellings);
    if (subscription == 0 || sock == 0 || n < 1 || n > MAX_SPELLINGS || !(max_rate >= 0)) {
        PyErr_SetString(PyExc_ValueError, "bad handles, spellings or max_rate");
        return -1;
    }
    memcpy(&self->f.take, &addresses[0], sizeof(void *));
    memcpy(&self->f.set_callback, &addresses[1], sizeof(void *));
    memcpy(&self->f.reset_error, &addresses[2], sizeof(void *));
    memcpy(&self->f.default_allocator, &addresses[3], sizeof(void *));
    memcpy(&self->f.publisher_rmw_handle, &addresses[4], sizeof(void *));
    memcpy(&self->f.gid_for_publisher, &addresses[5], sizeof(void *));
    memcpy(&self->f.send, &addresses[6], sizeof(void *));
    self->encoders = PyList_New(0);
    if (self->encoders == NULL) return -1;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *item = PyList_GET_ITEM(spellings, i);
        struct spelling *s = &self->spellings[self->nspellings];
        PyObject *type, *topic, *sender, *encoder;
        if (!PyArg_ParseTuple(item, "SSSO", &type, &topic, &sender, &encoder)) return -1;
        s->encoder = native_encoder_of(encoder);
        if (s->encoder == NULL) {
            PyErr_SetString(PyExc_TypeError, "spellings: (bytes, bytes, bytes, Encoder)");
            return -1;
        }
        if (PyList_Append(self->encoders, encoder) < 0) return -1;
        s->type = copy_buffer(type, &s->type_len);
        s->topic = copy_buffer(topic, &s->topic_len);
        s->sender = copy_buffer(sender, &s->sender_len);
        self->nspellings++;
        if (s->type == NULL || s->topic == NULL || s->sender == NULL) {
            PyErr_NoMemory();
            return -1;
        }
    }
    self->event_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (self->event_fd < 0) {
        PyErr_SetFromErrno(PyExc_OSError);
        return -1;
    }
    rcu_allocator allocator = self->f.default_allocator();
    self->message.buffer = allocator.allocate(INITIAL_CAPACITY, allocator.state);
    if (self->message.buffer == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    self->message.buffer_capacity = INITIAL_CAPACITY;
    self->message.allocator = allocator;
    self->subscription = (void *)(uintptr_t)subscription;
    self->sock = (void *)(uintptr_t)sock;
    self->period_ns = max_rate > 0 ? (int64_t)(1e9 / max_rate) : 0;
    self->next_ns = INT64_MIN;
    return 0;
}

static PyObject *ros_pump_start(RosPumpObject *self, PyObject *unused) {
    (void)unused;
    if (!self->callback_set) {
        if (self->f.set_callback(self->subscription, on_new_message, self) != 0) {
            self->f.reset_error();
            PyErr_SetString(PyExc_RuntimeError, "rcl refused the on-new-message callback");
            return NULL;
        }
        self->callback_set = 1;
    }
    Py_RETURN_NONE;
}

static PyObject *ros_pump_stop(RosPumpObject *self, PyObject *unused) {
    (void)unused;
    if (self->running) {
        PyErr_SetString(PyExc_RuntimeError, "stop while the pump runs");
        return NULL;
    }
    stop_callback(self);
    Py_RETURN_NONE;
}

/* set_active(types): the spellings Gazebo subscribers take now. */
static PyObject *ros_pump_set_active(RosPumpObject *self, PyObject *types) {
    if (!PyFrozenSet_Check(types) && !PySet_Check(types)) {
        PyErr_SetString(PyExc_TypeError, "a set of type names (bytes)");
        return NULL;
    }
    for (int i = 0; i < self->nspellings; i++) {
        struct spelling *s = &self->spellings[i];
        PyObject *name = PyBytes_FromStringAndSize((char *)s->type, (Py_ssize_t)s->type_len);
        if (name == NULL) return NULL;
        int found = PySet_Contains(types, name);
        Py_DECREF(name);
        if (found < 0) return NULL;
        s->active = found;
    }
    Py_RETURN_NONE;
}

/* ignore(publishers): skip what these rcl publishers (the bridge's own, on the same topic)
 * wrote. */
static PyObject *ros_pump_ignore(RosPumpObject *self, PyObject *publishers) {
    PyObject *sequence = PySequence_Fast(publishers, "a sequence of rcl publisher addresses");
    if (sequence == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(sequence);
    int count = 0;
    for (Py_ssize_t i = 0; i < n && count < MAX_IGNORED; i++) {
        void *publisher = PyLong_AsVoidPtr(PySequence_Fast_GET_ITEM(sequence, i));
        if (publisher == NULL) {
            Py_DECREF(sequence);
            if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "a null publisher");
            return NULL;
        }
        void *rmw = self->f.publisher_rmw_handle(publisher);
        rmw_gid gid;
        if (rmw == NULL || self->f.gid_for_publisher(rmw, &gid) != 0) {
            self->f.reset_error();
            continue;
        }
        memcpy(self->ignored[count++], gid.data, GID_SIZE);
    }
    Py_DECREF(sequence);
    self->nignored = count;
    return PyLong_FromLong(count);
}

/* run(wake_fd, timeout_ms) -> (events, refused CDR messages) */
static PyObject *ros_pump_run(RosPumpObject *self, PyObject *args) {
    int wake_fd;
    long timeout_ms;
    if (!PyArg_ParseTuple(args, "il", &wake_fd, &timeout_ms)) return NULL;
    if (self->running || !self->callback_set) {
        PyErr_SetString(PyExc_RuntimeError, "the pump runs already, or was not started");
        return NULL;
    }
    self->running = 1;
    int events;
    Py_BEGIN_ALLOW_THREADS;
    events = ros_loop(self, wake_fd, timeout_ms < 0 ? 0 : timeout_ms);
    Py_END_ALLOW_THREADS;
    self->running = 0;
    PyObject *refused = PyList_New((Py_ssize_t)self->nrefused);
    for (size_t i = 0; refused != NULL && i < self->nrefused; i++) {
        PyObject *cdr =
            PyBytes_FromStringAndSize((char *)self->refused[i], (Py_ssize_t)self->refused_len[i]);
        if (cdr == NULL) Py_CLEAR(refused);
        else PyList_SET_ITEM(refused, (Py_ssize_t)i, cdr);
    }
    clear_refused(self);
    if (refused == NULL) return NULL;
    return Py_BuildValue("(iN)", events, refused);
}

static PyObject *ros_pump_counts(RosPumpObject *self, PyObject *unused) {
    (void)unused;
    return Py_BuildValue("(KKKKK)", self->received, self->own_skipped, self->rate_limited,
                         self->published, self->take_errors);
}

static PyMethodDef ros_pump_methods[] = {
    {"start", (PyCFunction)ros_pump_start, METH_NOARGS, "set rcl's on-new-message callback"},
    {"stop", (PyCFunction)ros_pump_stop, METH_NOARGS, "clear it (before the subscription goes)"},
    {"set_active", (PyCFunction)ros_pump_set_active, METH_O,
     "set_active(types): the spellings sent, a set of type names"},
    {"ignore", (PyCFunction)ros_pump_ignore, METH_O,
     "ignore(publishers) -> count: skip samples of these rcl publishers (by GID)"},
    {"run", (PyCFunction)ros_pump_run, METH_VARARGS,
     "run(wake_fd, timeout_ms) -> (events, refused), the GIL released"},
    {"counts", (PyCFunction)ros_pump_counts, METH_NOARGS,
     "(received, own_skipped, rate_limited, published, take_errors) so far"},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject RosPumpType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.RosPump",
    .tp_basicsize = sizeof(RosPumpObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The per-message loop of one ROS -> Gazebo channel (docs/native.md §7).",
    .tp_new = ros_pump_new,
    .tp_init = (initproc)ros_pump_init,
    .tp_dealloc = (destructor)ros_pump_dealloc,
    .tp_methods = ros_pump_methods,
};

int ros_pump_register(PyObject *module) {
    if (PyType_Ready(&RosPumpType) < 0) return -1;
    Py_INCREF(&RosPumpType);
    if (PyModule_AddObject(module, "RosPump", (PyObject *)&RosPumpType) < 0) {
        Py_DECREF(&RosPumpType);
        return -1;
    }
    return 0;
}
