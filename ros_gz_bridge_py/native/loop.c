/* The one loop that runs every native Gazebo -> ROS channel of the process (docs/native.md §5).
 *
 * A channel's Pump (pump.c) holds its queue, routes and programs; the Loop holds the pumps and
 * sleeps in one epoll(7) over their sockets' ZMQ_FD descriptors, the connection monitors' and
 * its own wake-up eventfd, with the GIL released. However many channels there are, one thread
 * reads and publishes all their messages, so a fleet of robots costs no thread per topic and a
 * message costs no thread switch of its own.
 *
 * ZMQ_FD is edge-like: it is readable while libzmq has commands to process, and a recv that
 * returns EAGAIN has processed them all. So a socket is slept on only after a read found it
 * empty; until then it is "active" and read again on the next pass. Each pass gives every
 * active channel at most READ_BUDGET reads and DELIVER_BUDGET deliveries (and SLICE_NS of
 * them), in the order they became active, so a flooded channel cannot starve another: /clock
 * keeps its rate beside a hundred busy topics. A flooded channel's own queue drops its oldest
 * messages, as it did on a thread of its own.
 *
 * `run` returns to Python with the channels that need it (messages handed back, a monitor
 * event, a socket that cannot be read), when `wake` was called (from any thread: posted
 * connections, a closing channel), or when the timeout ends. Python adds and removes channels
 * between runs, on the loop's thread; a Python call on the sockets (connect, disconnect) may
 * process their commands, so Python names the channels it touched (`run`'s `touched`) and they
 * are read and their monitors asked again before the loop sleeps. */
#define PY_SSIZE_T_CLEAN
#include <errno.h>
#include <stdatomic.h>
#include <stdint.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include "pump.h"

#define READ_BUDGET 64
#define DELIVER_BUDGET 64
#define SLICE_NS 1000000LL
#define MAX_EVENTS 64

enum { EVENT_MONITOR = 2, EVENT_HANDED = 4, EVENT_BROKEN = 8 };

struct member {
    PyObject *object; /* the Pump, a strong reference */
    PumpObject *pump;
    void *sock, *monitor;
    int sock_fd, monitor_fd;
    int readable;      /* not known to be empty: read it before sleeping */
    int check_monitor; /* ask the monitor before sleeping */
    int active;        /* in the active list */
    int reported;      /* in this run's report */
    int events;        /* what Python is told */
    unsigned long long seen; /* pump_taken at the last `moved` */
};

typedef struct {
    PyObject_HEAD
    int epoll_fd, wake_fd;
    atomic_int running;
    atomic_int woken;
    struct member **members;
    size_t nmembers, capacity;
    struct member **active; /* capacity entries */
    size_t nactive;
    struct member **report; /* capacity entries */
    size_t nreport;
} LoopObject;

static int64_t monotonic_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

static void activate(LoopObject *self, struct member *m) {
    if (!m->active) {
        m->active = 1;
        self->active[self->nactive++] = m;
    }
}

static void report(LoopObject *self, struct member *m, int events) {
    m->events |= events;
    if (!m->reported) {
        m->reported = 1;
        self->report[self->nreport++] = m;
    }
}

/* One pass over the active channels: reads, deliveries, and what to tell Python. */
static void pass(LoopObject *self) {
    size_t kept = 0;
    for (size_t i = 0; i < self->nactive; i++) {
        struct member *m = self->active[i];
        if (m->check_monitor) {
            m->check_monitor = 0;
            if (pump_monitor_ready(m->pump, m->monitor)) report(self, m, EVENT_MONITOR);
        }
        if (m->readable) {
            int read = pump_read(m->pump, m->sock, READ_BUDGET);
            if (read != 0) m->readable = 0;
            if (read < 0) report(self, m, EVENT_BROKEN);
        }
        if (pump_queued(m->pump)) pump_deliver(m->pump, DELIVER_BUDGET, monotonic_ns() + SLICE_NS);
        if (pump_handed(m->pump)) report(self, m, EVENT_HANDED);
        if (m->readable || pump_queued(m->pump))
            self->active[kept++] = m;
        else
            m->active = 0;
    }
    self->nactive = kept;
}

static void drain_wake(LoopObject *self) {
    uint64_t count;
    ssize_t ignored = read(self->wake_fd, &count, sizeof count);
    (void)ignored;
}

/* Runs until something is reported, `wake` is called or `deadline` passes; 1 when woken. */
static int loop_run(LoopObject *self, int64_t deadline) {
    struct epoll_event events[MAX_EVENTS];
    for (;;) {
        if (atomic_exchange(&self->woken, 0)) {
            drain_wake(self);
            return 1;
        }
        pass(self);
        if (self->nreport) return 0;
        int64_t left = deadline - monotonic_ns();
        if (left <= 0) return 0; /* also under a flood: Python's share is due */
        if (self->nactive) continue;
        int ready = epoll_wait(self->epoll_fd, events, MAX_EVENTS, (int)((left + 999999) / 1000000));
        if (ready < 0 && errno != EINTR) return 0;
        for (int i = 0; i < ready; i++) {
            uintptr_t tag = (uintptr_t)events[i].data.ptr;
            if (tag == 0) { /* the wake-up: `woken` says it; drained here, since a wake that
                             * raced with the last check leaves the count behind */
                drain_wake(self);
                continue;
            }
            struct member *m = (struct member *)(tag & ~(uintptr_t)1);
            if (tag & 1)
                m->check_monitor = 1;
            else
                m->readable = 1;
            activate(self, m);
        }
    }
}

/* ---- Python methods ---------------------------------------------------------------------- */

static int idle(LoopObject *self) {
    if (self->epoll_fd < 0) {
        PyErr_SetString(PyExc_RuntimeError, "the Loop is not initialised");
        return -1;
    }
    if (atomic_load(&self->running)) {
        PyErr_SetString(PyExc_RuntimeError, "the Loop is running");
        return -1;
    }
    return 0;
}

static struct member *find(LoopObject *self, PyObject *object, size_t *index) {
    for (size_t i = 0; i < self->nmembers; i++)
        if (self->members[i]->object == object) {
            if (index != NULL) *index = i;
            return self->members[i];
        }
    return NULL;
}

static void unlist(struct member **list, size_t *n, struct member *m) {
    for (size_t i = 0; i < *n; i++)
        if (list[i] == m) {
            for (size_t k = i + 1; k < *n; k++) list[k - 1] = list[k];
            (*n)--;
            return;
        }
}

static void release(LoopObject *self, struct member *m) {
    epoll_ctl(self->epoll_fd, EPOLL_CTL_DEL, m->sock_fd, NULL);
    if (m->monitor_fd >= 0) epoll_ctl(self->epoll_fd, EPOLL_CTL_DEL, m->monitor_fd, NULL);
    pump_detach(m->pump);
    Py_DECREF(m->object);
    free(m);
}

static PyObject *loop_new(PyTypeObject *type, PyObject *args, PyObject *kwds) {
    LoopObject *self = (LoopObject *)type->tp_alloc(type, 0);
    (void)args;
    (void)kwds;
    if (self == NULL) return NULL;
    self->epoll_fd = self->wake_fd = -1;
    self->epoll_fd = epoll_create1(EPOLL_CLOEXEC);
    self->wake_fd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    struct epoll_event wake = {.events = EPOLLIN, .data.ptr = NULL};
    if (self->epoll_fd < 0 || self->wake_fd < 0 ||
        epoll_ctl(self->epoll_fd, EPOLL_CTL_ADD, self->wake_fd, &wake) < 0) {
        PyErr_SetFromErrno(PyExc_OSError);
        Py_DECREF(self);
        return NULL;
    }
    return (PyObject *)self;
}

static void loop_dealloc(LoopObject *self) {
    for (size_t i = 0; i < self->nmembers; i++) release(self, self->members[i]);
    free(self->members);
    free(self->active);
    free(self->report);
    if (self->epoll_fd >= 0) close(self->epoll_fd);
    if (self->wake_fd >= 0) close(self->wake_fd);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int grow(LoopObject *self) {
    if (self->nmembers < self->capacity) return 0;
    size_t capacity = self->capacity ? self->capacity * 2 : 16;
    struct member **lists[3] = {self->members, self->active, self->report};
    for (int i = 0; i < 3; i++) {
        struct member **grown = realloc(lists[i], capacity * sizeof *grown);
        if (grown == NULL) return -1;
        lists[i] = grown;
        if (i == 0) self->members = grown;
        if (i == 1) self->active = grown;
        if (i == 2) self->report = grown;
    }
    self->capacity = capacity;
    return 0;
}

/* add(pump, sock, monitor): run `pump` on the ZeroMQ socket `sock` (an address), with the
 * connection monitor `monitor` (an address, or 0). */
static PyObject *loop_add(LoopObject *self, PyObject *args) {
    PyObject *object;
    unsigned long long sock, monitor;
    if (idle(self) < 0 || !PyArg_ParseTuple(args, "OKK", &object, &sock, &monitor)) return NULL;
    PumpObject *pump = native_pump_of(object);
    if (pump == NULL || sock == 0) {
        PyErr_SetString(PyExc_TypeError, "add(pump, sock, monitor): an initialised Pump and a socket");
        return NULL;
    }
    if (find(self, object, NULL) != NULL || pump_attach(pump, &self->running) < 0) {
        PyErr_SetString(PyExc_RuntimeError, "the Pump already runs in a loop");
        return NULL;
    }
    struct member *m = calloc(1, sizeof *m);
    if (m == NULL || grow(self) < 0) {
        free(m);
        pump_detach(pump);
        return PyErr_NoMemory();
    }
    m->object = Py_NewRef(object);
    m->pump = pump;
    m->sock = (void *)(uintptr_t)sock;
    m->monitor = (void *)(uintptr_t)monitor;
    m->sock_fd = pump_zmq_fd(pump, m->sock);
    m->monitor_fd = monitor ? pump_zmq_fd(pump, m->monitor) : -1;
    struct epoll_event on_sock = {.events = EPOLLIN, .data.ptr = m};
    struct epoll_event on_monitor = {.events = EPOLLIN, .data.ptr = (char *)m + 1};
    int failed = m->sock_fd < 0 || (monitor && m->monitor_fd < 0) ||
                 epoll_ctl(self->epoll_fd, EPOLL_CTL_ADD, m->sock_fd, &on_sock) < 0;
    if (!failed && m->monitor_fd >= 0 &&
        epoll_ctl(self->epoll_fd, EPOLL_CTL_ADD, m->monitor_fd, &on_monitor) < 0) {
        epoll_ctl(self->epoll_fd, EPOLL_CTL_DEL, m->sock_fd, NULL);
        failed = 1;
    }
    if (failed) {
        pump_detach(pump);
        Py_DECREF(m->object);
        free(m);
        PyErr_SetString(PyExc_OSError, "the socket or its monitor has no descriptor to poll");
        return NULL;
    }
    self->members[self->nmembers++] = m;
    m->readable = m->check_monitor = 1;
    activate(self, m);
    Py_RETURN_NONE;
}

/* remove(pump): the loop no longer touches the pump nor its sockets. */
static PyObject *loop_remove(LoopObject *self, PyObject *object) {
    size_t index;
    if (idle(self) < 0) return NULL;
    struct member *m = find(self, object, &index);
    if (m == NULL) Py_RETURN_FALSE;
    self->members[index] = self->members[--self->nmembers];
    if (m->active) unlist(self->active, &self->nactive, m);
    if (m->reported) unlist(self->report, &self->nreport, m);
    release(self, m);
    Py_RETURN_TRUE;
}

/* run(timeout_ms, touched) -> (woken, [(pump, events)])
 * touched: the pumps whose sockets Python used since the last run (read and asked again). */
static PyObject *loop_run_method(LoopObject *self, PyObject *args) {
    long timeout_ms;
    PyObject *touched;
    if (idle(self) < 0 || !PyArg_ParseTuple(args, "lO", &timeout_ms, &touched)) return NULL;
    PyObject *sequence = PySequence_Fast(touched, "touched must be a sequence");
    if (sequence == NULL) return NULL;
    for (Py_ssize_t i = 0; i < PySequence_Fast_GET_SIZE(sequence); i++) {
        struct member *m = find(self, PySequence_Fast_GET_ITEM(sequence, i), NULL);
        if (m != NULL) {
            m->readable = m->check_monitor = 1;
            activate(self, m);
        }
    }
    Py_DECREF(sequence);
    for (size_t i = 0; i < self->nreport; i++) self->report[i]->reported = self->report[i]->events = 0;
    self->nreport = 0;
    int64_t deadline = monotonic_ns() + (timeout_ms < 0 ? 0 : (int64_t)timeout_ms) * 1000000LL;
    int woken;
    atomic_store(&self->running, 1);
    Py_BEGIN_ALLOW_THREADS;
    woken = loop_run(self, deadline);
    Py_END_ALLOW_THREADS;
    atomic_store(&self->running, 0);
    PyObject *reported = PyList_New((Py_ssize_t)self->nreport);
    for (size_t i = 0; reported != NULL && i < self->nreport; i++) {
        struct member *m = self->report[i];
        PyObject *item = Py_BuildValue("(Oi)", m->object, m->events);
        if (item == NULL) {
            Py_CLEAR(reported);
            break;
        }
        PyList_SET_ITEM(reported, (Py_ssize_t)i, item);
    }
    if (reported == NULL) return NULL;
    return Py_BuildValue("(NN)", PyBool_FromLong(woken), reported);
}

/* moved() -> [pump]: the pumps that read a message since the last call. */
static PyObject *loop_moved(LoopObject *self, PyObject *unused) {
    (void)unused;
    if (idle(self) < 0) return NULL;
    PyObject *moved = PyList_New(0);
    for (size_t i = 0; moved != NULL && i < self->nmembers; i++) {
        struct member *m = self->members[i];
        unsigned long long taken = pump_taken(m->pump);
        if (taken != m->seen && PyList_Append(moved, m->object) < 0) Py_CLEAR(moved);
        m->seen = taken;
    }
    return moved;
}

/* wake(): from any thread, makes a run return soon (at once when it sleeps). */
static PyObject *loop_wake(LoopObject *self, PyObject *unused) {
    (void)unused;
    if (self->wake_fd < 0) Py_RETURN_NONE;
    atomic_store(&self->woken, 1);
    uint64_t one = 1;
    ssize_t ignored = write(self->wake_fd, &one, sizeof one);
    (void)ignored;
    Py_RETURN_NONE;
}

static PyObject *loop_len(LoopObject *self, PyObject *unused) {
    (void)unused;
    return PyLong_FromSize_t(self->nmembers);
}

static PyMethodDef loop_methods[] = {
    {"add", (PyCFunction)loop_add, METH_VARARGS,
     "add(pump, sock, monitor): run the pump on the socket (addresses; monitor may be 0)"},
    {"remove", (PyCFunction)loop_remove, METH_O,
     "remove(pump) -> bool: the loop no longer touches the pump nor its sockets"},
    {"run", (PyCFunction)loop_run_method, METH_VARARGS,
     "run(timeout_ms, touched) -> (woken, [(pump, events)]), the GIL released"},
    {"moved", (PyCFunction)loop_moved, METH_NOARGS,
     "moved() -> [pump]: the pumps that read a message since the last call"},
    {"wake", (PyCFunction)loop_wake, METH_NOARGS, "wake(): a run returns soon (any thread)"},
    {"size", (PyCFunction)loop_len, METH_NOARGS, "size() -> the number of pumps"},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject LoopType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.Loop",
    .tp_basicsize = sizeof(LoopObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The one loop of every native Gazebo -> ROS channel (docs/native.md §5).",
    .tp_new = loop_new,
    .tp_dealloc = (destructor)loop_dealloc,
    .tp_methods = loop_methods,
};

int loop_register(PyObject *module) {
    if (PyType_Ready(&LoopType) < 0) return -1;
    Py_INCREF(&LoopType);
    if (PyModule_AddObject(module, "Loop", (PyObject *)&LoopType) < 0) {
        Py_DECREF(&LoopType);
        return -1;
    }
    if (PyModule_AddIntConstant(module, "EVENT_MONITOR", EVENT_MONITOR) < 0 ||
        PyModule_AddIntConstant(module, "EVENT_HANDED", EVENT_HANDED) < 0 ||
        PyModule_AddIntConstant(module, "EVENT_BROKEN", EVENT_BROKEN) < 0)
        return -1;
    return 0;
}
