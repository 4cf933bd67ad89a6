/* RosPump: one native ROS -> Gazebo channel, as Python makes, syncs and reads it
 * (docs/native.md §7; its per-message work: ros_pump_loop.c).
 *
 * Python makes it with the channel's rclpy subscription (on a node no executor spins), the
 * channel's own PUB socket and an encoder per spelling, adds it to its direction's Loop
 * (loop.c), tells it the spellings Gazebo subscribers take and the bridge's own publishers to
 * skip, and between the loop's runs takes what the encoders left to it and reads its counts.
 * The rcl, rmw, rcutils and libzmq functions rgb_ros_pump_functions names come from the
 * libraries rclpy and pyzmq loaded, their addresses passed by name (abi.py). */
#include "_native.h"

#include <string.h>
#include <sys/eventfd.h>
#include <unistd.h>

#define INITIAL_CAPACITY 4096

/* ---- Python -------------------------------------------------------------------------------- */

/* Every method first (rgb_member_usable). */
static int usable(RosPumpObject *self, int idle) {
    const char *unset = "the RosPump is not initialised (call __init__)";
    return rgb_member_usable(&self->member, idle, "RosPump", unset);
}

static void ros_pump_dealloc(RosPumpObject *self) {
    ros_pump_clear_callback(self);
    if (self->event_fd >= 0) close(self->event_fd);
    if (self->message.buffer != NULL)
        self->message.allocator.deallocate(self->message.buffer, self->message.allocator.state);
    for (int i = 0; i < self->nspellings; i++) {
        free(self->spellings[i].type);
        free(self->spellings[i].topic);
        free(self->spellings[i].sender);
    }
    for (int i = 0; i < MAX_SPELLINGS; i++) rgb_out_free(&self->out[i]);
    ros_pump_clear_refused(self);
    free(self->refused);
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

#define FUNCTION(name, field) {name, offsetof(struct ros_foreign, field)}
const struct rgb_function rgb_ros_pump_functions[] = {
    FUNCTION("rcl_take_serialized_message", take),
    FUNCTION("rcl_subscription_set_on_new_message_callback", set_callback),
    FUNCTION("rcutils_reset_error", reset_error),
    FUNCTION("rcutils_get_default_allocator", default_allocator),
    FUNCTION("rcl_publisher_get_rmw_handle", publisher_rmw_handle),
    FUNCTION("rmw_get_gid_for_publisher", gid_for_publisher),
    FUNCTION("zmq_send", send),
    {NULL, 0},
};

/* RosPump(functions, subscription, sock, spellings, max_rate)
 * functions: {name: address} of rgb_ros_pump_functions; spellings: [(type, topic, sender,
 * Encoder)], the configured spelling first. */
static int ros_pump_init(RosPumpObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {"functions", "subscription", "sock", "spellings", "max_rate", NULL};
    PyObject *functions, *spellings;
    unsigned long long subscription, sock;
    double max_rate;
    if (self->encoders != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "a RosPump is initialised once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "O!KKO!d", keywords, &PyDict_Type, &functions,
                                     &subscription, &sock, &PyList_Type, &spellings, &max_rate))
        return -1;
    if (rgb_functions(functions, rgb_ros_pump_functions, &self->f) < 0) return -1;
    Py_ssize_t n = PyList_GET_SIZE(spellings);
    if (subscription == 0 || sock == 0 || n < 1 || n > MAX_SPELLINGS || !(max_rate >= 0)) {
        PyErr_SetString(PyExc_ValueError, "bad handles, spellings or max_rate");
        return -1;
    }
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
    self->member.hooks = &rgb_ros_pump_hooks; /* last: a RosPump with hooks is whole */
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
        PyObject *cdr = PyBytes_FromStringAndSize((char *)self->refused[k].cdr,
                                                  (Py_ssize_t)self->refused[k].len);
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
    ros_pump_clear_refused(self);
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
    if (s != NULL && !self->failure) sent = ros_pump_send_frames(self, s, &out);
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
