/* RosPump: one native ROS -> Gazebo channel (docs/native.md §7), run by its direction's Loop
 * (loop.c) through the hooks below, with the GIL released.
 *
 * rcl tells of new messages through the subscription's on-new-message callback (an eventfd,
 * the descriptor the loop sleeps on); a turn takes each message serialized from the rclpy
 * subscription's rcl handle, skips it when one of the bridge's own publishers on the topic
 * wrote it (by publisher GID, as the C++ bridge does), passes it through max_rate, encodes it
 * (encode.c) in each spelling Gazebo subscribers take and sends it as the four data frames on
 * the channel's own ZeroMQ PUB socket. No Python runs per message; what an encoder leaves to
 * Python is handed back (take_handed), and Python converts it as without the native path. rcl,
 * rmw, rcutils and libzmq functions come from the libraries rclpy and pyzmq loaded (abi.py). */
#include "_native.h"

#include <errno.h>
#include <string.h>
#include <sys/eventfd.h>
#include <unistd.h>

/* rcutils_allocator_t, rcl_serialized_message_t, rmw_gid_t and rmw_message_info_t as Jazzy's
 * headers lay them out (abi.py checks the loaded rclpy). */
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
_Static_assert(sizeof(struct ros_foreign) == 7 * sizeof(void *), "the functions, in order");

enum { RCL_TAKE_FAILED = 401, ZMQ_SNDMORE_ = 2, ZMQ_DONTWAIT_ = 1 };
#define INITIAL_CAPACITY 4096
/* Retries of a frame send that a signal interrupted. */
#define EINTR_RETRIES 8
#define MAX_SPELLINGS 4
#define MAX_IGNORED 16

struct spelling {
    uint8_t *type, *topic, *sender;
    size_t type_len, topic_len, sender_len;
    struct rgb_encoder *encoder;
    int active;
};

typedef struct {
    PyObject_HEAD
    struct rgb_member member;
    struct ros_foreign f;
    void *subscription;
    void *sock;
    int event_fd; /* written by rcl's on-new-message callback */
    int callback_set;
    PyObject *encoders; /* list: keeps the Encoder objects alive; set by the first __init__ */
    struct spelling spellings[MAX_SPELLINGS];
    int nspellings;
    rcl_bytes message;
    struct rgb_out out[MAX_SPELLINGS];
    uint8_t ignored[MAX_IGNORED][GID_SIZE];
    int nignored;
    int64_t period_ns, next_ns;
    unsigned long long received, own_skipped, rate_limited, published, take_errors,
        send_failures, bytes_read;
    unsigned long long lost; /* messages for Python that could not be copied (no memory) */
    uint8_t **refused;
    size_t *refused_len;
    size_t nrefused, refused_cap;
    /* Set when the channel's socket or eventfd failed (an errno): it takes nothing more. */
    int failure;
} RosPumpObject;

/* rcl's on-new-message callback, on a middleware thread: wake the loop. */
static void on_new_message(const void *user_data, size_t number_of_events) {
    const RosPumpObject *self = user_data;
    uint64_t n = number_of_events ? number_of_events : 1;
    ssize_t written = write(self->event_fd, &n, sizeof n);
    (void)written; /* a full counter still wakes the loop */
}

static int admit(RosPumpObject *self) {
    if (self->period_ns <= 0) return 1;
    int64_t now = rgb_now_ns(CLOCK_MONOTONIC);
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

/* Hands a message to Python as a copy. When memory runs out it is counted as lost instead
 * (never handed over empty: an empty payload would be sent as an all-default message). */
static void refuse(RosPumpObject *self, const uint8_t *cdr, size_t len) {
    if (self->nrefused == self->refused_cap) {
        size_t cap = self->refused_cap ? self->refused_cap * 2 : 16;
        uint8_t **grown = realloc(self->refused, cap * sizeof *grown);
        if (grown != NULL) self->refused = grown;
        size_t *grown_len = realloc(self->refused_len, cap * sizeof *grown_len);
        if (grown_len != NULL) self->refused_len = grown_len;
        if (grown == NULL || grown_len == NULL) {
            self->lost++;
            return;
        }
        self->refused_cap = cap;
    }
    uint8_t *copy = rgb_copy(cdr, len);
    if (copy == NULL) {
        self->lost++;
        return;
    }
    self->refused[self->nrefused] = copy;
    self->refused_len[self->nrefused++] = len;
}

static void clear_refused(RosPumpObject *self) {
    for (size_t i = 0; i < self->nrefused; i++) free(self->refused[i]);
    self->nrefused = 0;
}

/* One frame; 0, or libzmq's errno. An interrupted send is tried again: PUB with ZMQ_DONTWAIT
 * never blocks (a subscriber over its high-water mark loses the message, as with the Python
 * path), so what remains are a signal, a closed socket (ENOTSOCK) or a terminated context. */
static int send_frame(RosPumpObject *self, const void *data, size_t len, int flags) {
    for (int attempt = 0;; attempt++) {
        if (self->f.send(self->sock, data, len, flags | ZMQ_DONTWAIT_) >= 0) return 0;
        int error = errno;
        if (error != EINTR || attempt == EINTR_RETRIES) return error ? error : EIO;
    }
}

/* The four data frames of one message. A failed first frame sent nothing: the message is
 * counted as a send failure. A later frame that fails would leave a part of a multipart
 * message in the socket, which the next message would complete into a wrong one: the socket
 * is not used again (`failure`). Returns 1 when sent. */
static int send_frames(RosPumpObject *self, const struct spelling *s, const struct rgb_out *out) {
    const char *empty = "";
    int error = send_frame(self, s->topic, s->topic_len, ZMQ_SNDMORE_);
    if (error) {
        self->send_failures++;
        if (error != EAGAIN) self->failure = error;
        return 0;
    }
    error = send_frame(self, s->sender, s->sender_len, ZMQ_SNDMORE_);
    if (!error)
        error = send_frame(self, out->len ? (const void *)out->data : empty, out->len,
                           ZMQ_SNDMORE_);
    if (!error) error = send_frame(self, s->type, s->type_len, 0);
    if (error) {
        self->send_failures++;
        self->failure = error;
        return 0;
    }
    return 1;
}

/* One taken message: encoded in the configured spelling (the first) and in each spelling a
 * subscriber takes, then sent in the latter; or handed to Python. Published when every send
 * went out. */
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
    int sent_all = 1;
    for (int i = 0; i < self->nspellings && !self->failure; i++) {
        struct spelling *s = &self->spellings[i];
        if (!s->active) continue;
        if (!send_frames(self, s, &self->out[encoded[i] >= 2 ? encoded[i] - 2 : i])) sent_all = 0;
    }
    if (sent_all && !self->failure) self->published++;
}

/* ---- the hooks (loop.c) -------------------------------------------------------------------- */

static int descriptors(struct rgb_member *m, int fds[RGB_MAX_FDS], const char **why) {
    (void)why;
    fds[0] = RGB_OWNER(RosPumpObject, m)->event_fd;
    return 1;
}

static int attach(struct rgb_member *m, const char **why) {
    RosPumpObject *self = RGB_OWNER(RosPumpObject, m);
    if (self->f.set_callback(self->subscription, on_new_message, self) != 0) {
        self->f.reset_error();
        *why = "rcl refused the on-new-message callback";
        return -1;
    }
    self->callback_set = 1;
    self->failure = 0;
    return 0;
}

static void clear_callback(RosPumpObject *self) {
    if (self->callback_set) {
        self->f.set_callback(self->subscription, NULL, NULL);
        self->f.reset_error();
        self->callback_set = 0;
    }
}

static void detach(struct rgb_member *m) {
    RosPumpObject *self = RGB_OWNER(RosPumpObject, m);
    clear_callback(self);
    clear_refused(self);
}

/* Takes and handles waiting messages within the budget; an eventfd or a socket that failed
 * takes the channel off (RGB_EVENT_BROKEN: the loop sleeps on it no more). */
static int turn(struct rgb_member *m, unsigned fired, const struct rgb_budget *budget) {
    RosPumpObject *self = RGB_OWNER(RosPumpObject, m);
    uint64_t count;
    if (fired & RGB_FIRED_ERROR)
        self->failure = EBADF;
    else if ((fired & 1) && read(self->event_fd, &count, sizeof count) < 0 && errno != EAGAIN)
        self->failure = errno;
    int taken = 0;
    int64_t slice_end = rgb_now_ns(CLOCK_MONOTONIC) + budget->slice_ns;
    while (taken < budget->messages && !self->failure) {
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
        self->bytes_read += self->message.buffer_length;
        if (is_ignored(self, &info.publisher_gid)) {
            self->own_skipped++;
        } else if (!admit(self)) {
            self->rate_limited++;
        } else {
            deliver(self, self->message.buffer, self->message.buffer_length);
        }
        if (rgb_now_ns(CLOCK_MONOTONIC) >= slice_end) {
            taken = budget->messages; /* more may wait: again at once */
            break;
        }
    }
    int events = self->nrefused ? RGB_EVENT_HANDED : 0;
    if (self->failure) return events | RGB_EVENT_BROKEN;
    return events | (taken == budget->messages ? RGB_AGAIN : 0);
}

static unsigned long long progress(const struct rgb_member *m) {
    return RGB_OWNER(RosPumpObject, m)->received;
}

static const struct rgb_hooks hooks = {descriptors, attach, detach, turn, progress};

/* ---- Python -------------------------------------------------------------------------------- */

/* Every method first: an object made by __new__ alone has no functions to call. */
static int usable(RosPumpObject *self, int idle) {
    if (self->member.hooks == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "the RosPump is not initialised (call __init__)");
        return -1;
    }
    return idle ? rgb_member_idle(&self->member, "RosPump") : 0;
}

static void ros_pump_dealloc(RosPumpObject *self) {
    clear_callback(self);
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
    *len = (size_t)PyBytes_GET_SIZE(bytes);
    return rgb_copy(PyBytes_AS_STRING(bytes), *len);
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
    if (rgb_addresses(functions, addresses, sizeof addresses / sizeof *addresses) < 0) return -1;
    Py_ssize_t n = PyList_GET_SIZE(spellings);
    if (subscription == 0 || sock == 0 || n < 1 || n > MAX_SPELLINGS || !(max_rate >= 0)) {
        PyErr_SetString(PyExc_ValueError, "bad handles, spellings or max_rate");
        return -1;
    }
    memcpy(&self->f, addresses, sizeof self->f); /* the same order, all pointers */
    self->encoders = PyList_New(0);
    if (self->encoders == NULL) return -1;
    for (Py_ssize_t i = 0; i < n; i++) {
        struct spelling *s = &self->spellings[self->nspellings];
        PyObject *type, *topic, *sender, *encoder;
        if (!PyArg_ParseTuple(PyList_GET_ITEM(spellings, i), "SSSO", &type, &topic, &sender,
                              &encoder))
            return -1;
        s->encoder = rgb_encoder_of(encoder);
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
    self->member.hooks = &hooks; /* last: a RosPump with hooks is whole */
    return 0;
}

/* set_active(types): the spellings Gazebo subscribers take now. */
static PyObject *ros_pump_set_active(RosPumpObject *self, PyObject *types) {
    if (usable(self, 1) < 0) return NULL;
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
    if (usable(self, 1) < 0) return NULL;
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

/* take_handed() -> [CDR message]: what the encoders left to Python since the last call. A
 * message whose bytes object cannot be made (no memory) is counted as lost and the others still
 * go; where the list cannot grow, the messages it would carry are counted as lost and
 * MemoryError is raised. */
static PyObject *ros_pump_take_handed(RosPumpObject *self, PyObject *unused) {
    (void)unused;
    if (usable(self, 1) < 0) return NULL;
    PyObject *refused = PyList_New(0);
    if (refused == NULL) self->lost += self->nrefused;
    for (size_t k = 0; refused != NULL && k < self->nrefused; k++) {
        PyObject *cdr = PyBytes_FromStringAndSize((char *)self->refused[k],
                                                  (Py_ssize_t)self->refused_len[k]);
        if (cdr == NULL) {
            PyErr_Clear();
            self->lost++;
            continue;
        }
        if (PyList_Append(refused, cdr) < 0) {
            self->lost += self->nrefused - k + (size_t)PyList_GET_SIZE(refused);
            Py_CLEAR(refused);
        }
        Py_DECREF(cdr);
    }
    clear_refused(self);
    return refused;
}

/* send(type, payload) -> bool: the four data frames of `payload` in the spelling whose type
 * frame is `type`, from Python (the fallback thread, which converts what the encoders left to
 * it) under the loop's mutex: the channel's socket is used by one thread at a time. False
 * where no spelling has that type, the send failed or the socket failed before. */
static PyObject *ros_pump_send(RosPumpObject *self, PyObject *args) {
    Py_buffer type, payload;
    if (usable(self, 0) < 0 || !PyArg_ParseTuple(args, "y*y*", &type, &payload)) return NULL;
    const struct spelling *s = NULL;
    for (int i = 0; s == NULL && i < self->nspellings; i++)
        if (self->spellings[i].type_len == (size_t)type.len &&
            !memcmp(self->spellings[i].type, type.buf, (size_t)type.len))
            s = &self->spellings[i];
    struct rgb_out out = {.data = payload.buf, .len = (size_t)payload.len};
    int sent = 0;
    Py_BEGIN_ALLOW_THREADS;
    pthread_mutex_t *lock = self->member.lock; /* NULL out of a loop: no other sender */
    if (lock != NULL) pthread_mutex_lock(lock);
    if (s != NULL && !self->failure) sent = send_frames(self, s, &out);
    if (lock != NULL) pthread_mutex_unlock(lock);
    Py_END_ALLOW_THREADS;
    PyBuffer_Release(&type);
    PyBuffer_Release(&payload);
    return PyBool_FromLong(sent);
}

static PyObject *ros_pump_counts(RosPumpObject *self, PyObject *unused) {
    (void)unused;
    if (usable(self, 0) < 0) return NULL;
    return rgb_record(rgb_records.ros_pump_counts,
                      Py_BuildValue("(KKKKKKKK)", self->received, self->own_skipped,
                                    self->rate_limited, self->published, self->take_errors,
                                    self->send_failures, self->lost, self->bytes_read));
}

static PyObject *ros_pump_failure(RosPumpObject *self, void *closure) {
    (void)closure;
    return PyLong_FromLong(self->failure);
}

static PyMethodDef ros_pump_methods[] = {
    {"set_active", (PyCFunction)ros_pump_set_active, METH_O,
     "set_active(types): the spellings sent, a set of type names"},
    {"ignore", (PyCFunction)ros_pump_ignore, METH_O,
     "ignore(publishers) -> count: skip samples of these rcl publishers (by GID)"},
    {"take_handed", (PyCFunction)ros_pump_take_handed, METH_NOARGS,
     "take_handed() -> [bytes]: the CDR messages the encoders left to Python"},
    {"send", (PyCFunction)ros_pump_send, METH_VARARGS,
     "send(type, payload) -> bool: the data frames, under the loop's mutex"},
    {"counts", (PyCFunction)ros_pump_counts, METH_NOARGS, "counts() -> RosPumpCounts so far"},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef ros_pump_getset[] = {
    {"failure", (getter)ros_pump_failure, NULL,
     "the errno that took the channel off its loop (its socket or eventfd failed), or 0", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject rgb_RosPumpType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.RosPump",
    .tp_basicsize = sizeof(RosPumpObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "One native ROS -> Gazebo channel, run by a Loop (docs/native.md §7).",
    .tp_new = ros_pump_new,
    .tp_init = (initproc)ros_pump_init,
    .tp_dealloc = (destructor)ros_pump_dealloc,
    .tp_methods = ros_pump_methods,
    .tp_getset = ros_pump_getset,
};
