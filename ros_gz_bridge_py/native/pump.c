/* Pump: one native Gazebo -> ROS channel, as Python makes, teaches and reads it
 * (docs/native.md §5; its per-message work: pump_loop.c).
 *
 * A Pump is one channel's state: its routes, its queue, its programs, its publisher. Python
 * makes it with the channel's ROS publisher, gives it the topic's socket (`read_from`), and
 * adds it to its direction's Loop (loop.c). Between the loop's runs, Python takes what the pump
 * left to it (`take_handed`), tells it the routes of the senders it judged (`learn`) and reads
 * its counts. libzmq and rcl are the libraries pyzmq and rclpy already loaded: Python finds
 * the functions rgb_pump_functions names there and passes their addresses by name (abi.py). */
#include "_native.h"

#include <string.h>

#define FUNCTION(name, field) {name, offsetof(struct zmq_foreign, field)}
const struct rgb_function rgb_pump_functions[] = {
    FUNCTION("zmq_msg_init", msg_init),     FUNCTION("zmq_msg_recv", msg_recv),
    FUNCTION("zmq_msg_close", msg_close),   FUNCTION("zmq_msg_data", msg_data),
    FUNCTION("zmq_msg_size", msg_size),     FUNCTION("zmq_msg_more", msg_more),
    FUNCTION("zmq_getsockopt", getsockopt), FUNCTION("rcl_publish_serialized_message", publish),
    FUNCTION("rcutils_reset_error", reset_error), {NULL, 0},
};

#define MAX_ROUTES 1024
/* Routes a full table keeps: the most recently used (and those a waiting message names). */
#define KEEP_ROUTES (MAX_ROUTES / 2)

/* A peer is as usable as the pump that reads for it (its loop runs both). */
int pump_usable(PumpObject *self, int idle) {
    if (rgb_member_usable(&self->member, idle, "Pump", "the Pump is not initialised") < 0)
        return -1;
    return self->reader == NULL ? 0 : pump_usable(self->reader, idle);
}

int pump_out_of_loop(PumpObject *self, const char *what) {
    if (pump_usable(self, 0) < 0) return -1;
    if (self->member.running == NULL && self->reader == NULL) return 0;
    PyErr_Format(PyExc_RuntimeError, "%s while a loop runs the pump, or another reads for it",
                 what);
    return -1;
}

/* ---- routes -------------------------------------------------------------------------------- */

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
    int *renumber = malloc(n * sizeof *renumber); /* a kept route's new index; -1: forgotten */
    uint64_t *uses = malloc(n * sizeof *uses);
    if (renumber == NULL || uses == NULL) { /* no memory: forget them all */
        free(renumber);
        free(uses);
        self->dropped += self->count + self->nhanded;
        pump_clear_ring(self);
        pump_clear_handover(self);
        clear_routes(self);
        return;
    }
    for (size_t i = 0; i < n; i++) uses[i] = self->routes[i].used;
    qsort(uses, n, sizeof *uses, newest_first);
    uint64_t oldest_kept = uses[KEEP_ROUTES - 1];
    for (size_t i = 0; i < n; i++) renumber[i] = self->routes[i].used > oldest_kept ? 0 : -1;
    for (size_t i = 0; i < self->count; i++)
        renumber[self->ring[(self->head + i) % self->capacity].route] = 0;
    for (size_t i = 0; i < self->nhanded; i++)
        if (self->handover[i].kind != HANDED_UNROUTED) renumber[self->handover[i].route] = 0;
    int kept = 0;
    for (size_t i = 0; i < n; i++) {
        if (renumber[i] >= 0) {
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
        if (self->handover[i].kind != HANDED_UNROUTED)
            self->handover[i].route = renumber[self->handover[i].route];
    self->nroutes = kept;
    free(renumber);
    free(uses);
}

/* ---- the type ------------------------------------------------------------------------------ */

static void pump_dealloc(PumpObject *self) {
    pump_release_peers(self);
    if (self->ring != NULL) pump_clear_ring(self);
    free(self->ring);
    pump_clear_handover(self);
    free(self->handover);
    clear_routes(self);
    for (int i = 0; i < self->nprograms; i++) free(self->programs[i].type);
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

/* Pump(topic, functions, publisher, programs, capacity, max_rate, max_bytes)
 * functions: {name: address} of rgb_pump_functions; programs: {wire type (bytes): Program}. */
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
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "y*O!KO!ndn", keywords, &topic, &PyDict_Type,
                                     &functions, &publisher, &PyDict_Type, &programs, &capacity,
                                     &max_rate, &max_bytes))
        return -1;
    int result = -1;
    if (rgb_functions(functions, rgb_pump_functions, &self->f) < 0) goto done;
    if ((publisher == 0 && PyDict_Size(programs) > 0) || capacity < 1 ||
        capacity > (1 << 24) || !(max_rate >= 0) || max_bytes < 1) {
        PyErr_SetString(PyExc_ValueError, "publisher, capacity, max_rate or max_bytes out of range");
        goto done;
    }
    self->publisher = (void *)(uintptr_t)publisher;
    Py_ssize_t n = PyDict_Size(programs);
    self->programs = calloc((size_t)n + 1, sizeof *self->programs);
    self->ring = calloc((size_t)capacity, sizeof *self->ring);
    if (self->programs == NULL || self->ring == NULL) {
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
        struct rgb_program *program = rgb_program_of(value);
        if (!PyBytes_Check(key) || program == NULL) {
            PyErr_SetString(PyExc_TypeError, "programs: {bytes: Program}");
            goto done;
        }
        if (PyList_Append(self->program_objects, value) < 0) goto done;
        struct pump_program *p = &self->programs[self->nprograms++];
        p->program = program;
        p->type_len = (size_t)PyBytes_GET_SIZE(key);
        p->type = rgb_copy(PyBytes_AS_STRING(key), p->type_len);
        if (p->type == NULL) {
            PyErr_NoMemory();
            goto done;
        }
    }
    self->period_ns = max_rate > 0 ? (int64_t)(1e9 / max_rate) : 0;
    self->next_ns = INT64_MIN;
    self->topic = rgb_copy(topic.buf, (size_t)topic.len);
    if (self->topic == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    self->topic_len = (size_t)topic.len;
    self->member.hooks = &rgb_pump_hooks; /* last: a Pump with hooks is whole */
    result = 0;
done:
    PyBuffer_Release(&topic);
    return result;
}

/* read_from(sock, monitor): the socket the loop reads (an address), and its connection monitor
 * (an address, or 0); only out of a loop. */
static PyObject *pump_read_from(PumpObject *self, PyObject *args) {
    unsigned long long sock, monitor;
    if (pump_out_of_loop(self, "read_from") < 0 ||
        !PyArg_ParseTuple(args, "KK", &sock, &monitor))
        return NULL;
    self->sock = (void *)(uintptr_t)sock;
    self->monitor = (void *)(uintptr_t)monitor;
    Py_RETURN_NONE;
}

/* learn(sender, msg_type, take): what messages of (sender, type) get from now on. */
static PyObject *pump_learn(PumpObject *self, PyObject *args) {
    Py_buffer sender, type;
    int take;
    if (pump_usable(self, 1) < 0 || !PyArg_ParseTuple(args, "y*y*p", &sender, &type, &take))
        return NULL;
    PyObject *result = NULL;
    int program = -1;
    for (int i = 0; take && i < self->nprograms; i++)
        if (self->programs[i].type_len == (size_t)type.len &&
            !memcmp(self->programs[i].type, type.buf, (size_t)type.len))
            program = i;
    if (take && program < 0) { /* taken, but no program: stays with Python */
        result = Py_NewRef(Py_False);
        goto done;
    }
    if (pump_find_route(self, sender.buf, (size_t)sender.len, type.buf, (size_t)type.len) < 0) {
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
        r->sender = rgb_copy(sender.buf, (size_t)sender.len);
        r->type = rgb_copy(type.buf, (size_t)type.len);
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

/* The socket read for the pump is replaced: what its reads left waiting goes. A route names a
 * sender and a type of the pump's topic, whichever socket brings them, so the routes stay: the
 * new socket's messages go natively at once, not copied for Python first. */
static PyObject *pump_forget(PumpObject *self, PyObject *unused) {
    (void)unused;
    if (pump_out_of_loop(self, "forget") < 0) return NULL;
    self->dropped += self->count + self->nhanded; /* their socket is gone: counted, not lost silently */
    pump_clear_ring(self);
    pump_clear_handover(self);
    Py_RETURN_NONE;
}

/* One handed message for Python: its frames (a list of bytes), a Refused or a TooLarge. */
static PyObject *handed_item(PumpObject *self, const struct handed *h) {
    if (h->kind == HANDED_UNROUTED) {
        PyObject *frames = PyList_New(h->nframes);
        for (int k = 0; frames != NULL && k < h->nframes; k++) {
            PyObject *frame = PyBytes_FromStringAndSize((char *)h->data[k], (Py_ssize_t)h->size[k]);
            if (frame == NULL) Py_CLEAR(frames);
            else PyList_SET_ITEM(frames, k, frame);
        }
        return frames;
    }
    const struct route *r = &self->routes[h->route];
    if (h->kind == HANDED_TOO_LARGE)
        return rgb_record(rgb_records.too_large,
                          Py_BuildValue("(y#y#nnn)", (char *)r->sender, (Py_ssize_t)r->sender_len,
                                        (char *)r->type, (Py_ssize_t)r->type_len,
                                        rgb_clamp(h->items), rgb_clamp(h->least),
                                        rgb_clamp(h->payload_size)));
    return rgb_record(rgb_records.refused,
                      Py_BuildValue("(y#y#y#i)", (char *)r->sender, (Py_ssize_t)r->sender_len,
                                    (char *)r->type, (Py_ssize_t)r->type_len, (char *)h->data[0],
                                    (Py_ssize_t)h->size[0], h->status));
}

/* take_handed() -> Handover: what the loop left to Python since the last call. A message
 * whose Python copy cannot be made (no memory) is counted as lost, as in pump_loop.c's
 * hand_frames, and the others are still handed; when a list itself cannot grow, what it would
 * have held is lost and MemoryError raised. */
static PyObject *pump_take_handed(PumpObject *self, PyObject *unused) {
    (void)unused;
    if (pump_usable(self, 1) < 0) return NULL;
    PyObject *lists[3] = {PyList_New(0), PyList_New(0), PyList_New(0)};
    int failed = lists[0] == NULL || lists[1] == NULL || lists[2] == NULL;
    if (failed) self->lost += self->nhanded;
    for (size_t i = 0; !failed && i < self->nhanded; i++) {
        PyObject *item = handed_item(self, &self->handover[i]);
        if (item == NULL) {
            PyErr_Clear();
            self->lost++;
            continue;
        }
        if (PyList_Append(lists[self->handover[i].kind], item) < 0) {
            self->lost += self->nhanded - i + (size_t)PyList_GET_SIZE(lists[0]) +
                          (size_t)PyList_GET_SIZE(lists[1]) + (size_t)PyList_GET_SIZE(lists[2]);
            failed = 1;
        }
        Py_DECREF(item);
    }
    pump_clear_handover(self);
    PyObject *handover = NULL;
    if (!failed) {
        handover = rgb_record(rgb_records.handover,
                              Py_BuildValue("(OOOn)", lists[0], lists[1], lists[2],
                                            rgb_clamp(self->grown)));
        if (handover != NULL) self->grown = 0;
    }
    for (int k = 0; k < 3; k++) Py_XDECREF(lists[k]);
    if (failed && !PyErr_Occurred()) PyErr_NoMemory();
    return handover;
}

/* watch(size): payloads larger than `size` are told (Handover.grown); a negative size: none. */
static PyObject *pump_watch(PumpObject *self, PyObject *arg) {
    if (pump_usable(self, 1) < 0) return NULL;
    long long size = PyLong_AsLongLong(arg);
    if (size == -1 && PyErr_Occurred()) return NULL;
    self->watch_above = size < 0 ? SIZE_MAX : (size_t)size;
    Py_RETURN_NONE;
}

static PyObject *pump_counts(PumpObject *self, PyObject *unused) {
    (void)unused;
    return rgb_record(rgb_records.pump_counts,
                      Py_BuildValue("(KKKKKKKK)", self->received, self->rate_limited,
                                    self->published, self->dropped, self->skipped, self->lost,
                                    self->taken, self->bytes_read));
}

static PyObject *pump_dropped_sender(PumpObject *self, void *closure) {
    (void)closure;
    return PyBytes_FromStringAndSize((char *)self->drop_sender, (Py_ssize_t)self->drop_sender_len);
}

static PyObject *pump_begin_publication_method(PumpObject *self, PyObject *unused) {
    (void)unused;
    return PyLong_FromUnsignedLongLong(pump_begin_publication(self, 0));
}

/* The digest of `cdr` (a bytes-like object; None: 0, not known) into *digest. */
static int digest_of(PyObject *cdr, uint64_t *digest) {
    *digest = 0;
    if (cdr == Py_None) return 0;
    Py_buffer view;
    if (PyObject_GetBuffer(cdr, &view, PyBUF_SIMPLE) < 0) return -1;
    *digest = rgb_cdr_digest(view.buf, (size_t)view.len);
    PyBuffer_Release(&view);
    return 0;
}

static PyObject *pump_end_publication_method(PumpObject *self, PyObject *args) {
    unsigned long long sequence;
    int ok;
    PyObject *written = Py_None;
    uint64_t digest;
    if (!PyArg_ParseTuple(args, "Kp|O", &sequence, &ok, &written)) return NULL;
    if (digest_of(written, &digest) < 0) return NULL;
    pump_end_publication(self, sequence, ok, digest);
    Py_RETURN_NONE;
}

static PyObject *pump_is_own(PumpObject *self, PyObject *args) {
    unsigned long long sequence;
    long long stamp;
    PyObject *received = Py_None;
    uint64_t digest;
    if (!PyArg_ParseTuple(args, "KL|O", &sequence, &stamp, &received)) return NULL;
    if (digest_of(received, &digest) < 0) return NULL;
    pthread_mutex_lock(&self->lock);
    struct window *w = &self->windows[sequence % PUMP_HISTORY];
    int own = sequence != 0 && w->sequence == sequence && w->start <= stamp && stamp <= w->end &&
              (!digest || !w->digest || digest == w->digest);
    pthread_mutex_unlock(&self->lock);
    return PyBool_FromLong(own);
}

static PyObject *pump_guard(PumpObject *self, PyObject *unused) {
    (void)unused;
    __atomic_store_n(&self->guarded, 1, __ATOMIC_RELAXED);
    Py_RETURN_NONE;
}

static PyMethodDef pump_methods[] = {
    {"read_from", (PyCFunction)pump_read_from, METH_VARARGS,
     "read_from(sock, monitor): the socket a loop reads (addresses; monitor may be 0)"},
    {"share", (PyCFunction)pump_share, METH_O,
     "share(peers): the socket read_from names carries the peers' topics (Pumps), and no "
     "message of this pump's own"},
    {"learn", (PyCFunction)pump_learn, METH_VARARGS,
     "learn(sender, msg_type, take) -> bool: route messages of (sender, type) natively (take) "
     "or skip them; False where no program takes msg_type"},
    {"forget", (PyCFunction)pump_forget, METH_NOARGS,
     "forget the queued and handed messages (counted dropped); the routes stay"},
    {"take_handed", (PyCFunction)pump_take_handed, METH_NOARGS,
     "take_handed() -> Handover: what the loop left to Python since the last call"},
    {"watch", (PyCFunction)pump_watch, METH_O,
     "watch(size): payloads larger than size are told in Handover.grown (negative: none)"},
    {"counts", (PyCFunction)pump_counts, METH_NOARGS, "counts() -> PumpCounts so far"},
    {"begin_publication", (PyCFunction)pump_begin_publication_method, METH_NOARGS,
     "a publication made from Python on the same publisher: its sequence number"},
    {"end_publication", (PyCFunction)pump_end_publication_method, METH_VARARGS,
     "end_publication(sequence, ok, written=None): written, the CDR bytes published if known"},
    {"is_own", (PyCFunction)pump_is_own, METH_VARARGS,
     "is_own(sequence, source_timestamp_ns, received=None) -> bool: a sample this publisher "
     "wrote (received, its CDR bytes if known, must be what was published)"},
    {"guard", (PyCFunction)pump_guard, METH_NOARGS,
     "guard(): keep a digest of each publication from now on (the loop guard judges the topic)"},
    {NULL, NULL, 0, NULL},
};

static PyObject *pump_handing(PumpObject *self, void *closure) {
    (void)closure;
    return PyBool_FromLong(self->nhanded || self->grown);
}

static PyGetSetDef pump_getset[] = {
    {"handing", (getter)pump_handing, NULL,
     "whether take_handed has something (its reader's turns report it for every peer)", NULL},
    {"dropped_sender", (getter)pump_dropped_sender, NULL,
     "the sender of the last payload dropped (b'' before any)", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject rgb_PumpType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.Pump",
    .tp_basicsize = sizeof(PumpObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The per-message work of one Gazebo -> ROS channel (docs/native.md §5).",
    .tp_new = pump_new,
    .tp_init = (initproc)pump_init,
    .tp_dealloc = (destructor)pump_dealloc,
    .tp_methods = pump_methods,
    .tp_getset = pump_getset,
};
