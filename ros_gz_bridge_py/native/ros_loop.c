/* The one loop that serves every native ROS -> Gazebo channel of the process (docs/native.md
 * §7).
 *
 * One epoll set holds each attached channel's eventfd (rcl's on-new-message callback writes
 * it) and the loop's own wake-up eventfd. A round waits in epoll_wait, queues the channels
 * whose eventfd fired, then lets each queued channel take and send at most BUDGET messages
 * (ros_pump.c); a channel with more waiting stays queued for the next round, which then does
 * not sleep. So a flooded channel takes its turn with the others instead of before them, and
 * the wake-up fd is looked at every round. Rounds run with the GIL released, under the loop's
 * mutex; `add` and `remove` take the same mutex, so once `remove` returns no round touches the
 * channel (its socket and subscription may go). A channel is named in epoll by its slot and a
 * generation, so an event read before a removal cannot reach a channel that left.
 *
 * `run` returns to Python when a channel left messages to Python or its socket failed, when
 * `wake` was called, or at the timeout; with the channels that moved since the last return
 * (took a message, handed some back, failed), so that Python works only for those. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <time.h>
#include <unistd.h>

#include "ros_pump.h"

/* Messages a channel takes per round before the others have theirs. */
#define BUDGET 64
#define MAX_EVENTS 64
/* The epoll token of the wake-up fd (a channel's is its slot and generation, never this). */
#define WAKE_TOKEN UINT64_MAX

enum { RUN_TIMEOUT = 0, RUN_WAKE = 1, RUN_HANDED = 2, RUN_FAILED = 3 };

typedef struct {
    PyObject_HEAD
    int epoll_fd, wake_fd; /* -1 until __init__ */
    int initialised;
    pthread_mutex_t lock;
    RosPumpObject **slots; /* a strong reference each; NULL where free */
    uint32_t *generations;
    int nslots;
    int *ready; /* slots queued for the next round, in order */
    int nready;
    int *moved; /* slots that moved since `run` last returned */
    int nmoved;
    int running;
    int error; /* an errno that ended a run: epoll itself failed */
} RosLoopObject;

static uint64_t token_of(const RosLoopObject *self, int slot) {
    return ((uint64_t)self->generations[slot] << 32) | (uint32_t)slot;
}

static RosPumpObject *pump_of(const RosLoopObject *self, uint64_t token) {
    uint32_t slot = (uint32_t)token;
    if (slot >= (uint32_t)self->nslots || self->slots[slot] == NULL) return NULL;
    return token_of(self, (int)slot) == token ? self->slots[slot] : NULL;
}

static void queue(RosLoopObject *self, RosPumpObject *pump) {
    if (!pump->queued) {
        pump->queued = 1;
        self->ready[self->nready++] = pump->slot;
    }
}

static void mark_moved(RosLoopObject *self, RosPumpObject *pump) {
    if (!pump->moved) {
        pump->moved = 1;
        self->moved[self->nmoved++] = pump->slot;
    }
}

static void forget(int *slots, int *count, int slot) {
    for (int i = 0; i < *count; i++)
        if (slots[i] == slot) {
            memmove(&slots[i], &slots[i + 1], (size_t)(*count - i - 1) * sizeof *slots);
            (*count)--;
            return;
        }
}

/* A channel whose socket or eventfd failed: out of epoll and of the queue, reported. */
static void fail(RosLoopObject *self, RosPumpObject *pump, int error) {
    if (!pump->failure) pump->failure = error ? error : EIO;
    epoll_ctl(self->epoll_fd, EPOLL_CTL_DEL, pump->event_fd, NULL);
    mark_moved(self, pump);
}

static int64_t monotonic_ms(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* One round, under the lock: the events read, then a turn of each queued channel. Returns
 * whether something must go to Python now (messages left to it, a failure). */
static int round_of(RosLoopObject *self, const struct epoll_event *events, int n, int *woke) {
    int handed = 0;
    for (int i = 0; i < n; i++) {
        if (events[i].data.u64 == WAKE_TOKEN) {
            uint64_t count;
            ssize_t got = read(self->wake_fd, &count, sizeof count);
            (void)got;
            *woke = 1;
            continue;
        }
        RosPumpObject *pump = pump_of(self, events[i].data.u64);
        if (pump == NULL || pump->failure) continue; /* removed meanwhile */
        if (events[i].events & (EPOLLERR | EPOLLHUP)) {
            fail(self, pump, EBADF);
            handed = 1;
            continue;
        }
        uint64_t count;
        if (read(pump->event_fd, &count, sizeof count) < 0 && errno != EAGAIN) {
            fail(self, pump, errno);
            handed = 1;
            continue;
        }
        queue(self, pump);
    }
    int turns = self->nready, kept = 0;
    for (int i = 0; i < turns; i++) {
        RosPumpObject *pump = self->slots[self->ready[i]];
        int taken = ros_pump_drain(pump, BUDGET);
        if (taken) mark_moved(self, pump);
        if (pump->failure) {
            fail(self, pump, pump->failure);
            pump->queued = 0;
        } else if (taken == BUDGET) {
            self->ready[kept++] = pump->slot; /* more may wait: again next round */
        } else {
            pump->queued = 0;
        }
        if (pump->nrefused || pump->failure) handed = 1;
    }
    self->nready = kept;
    return handed;
}

static int loop(RosLoopObject *self, long timeout_ms) {
    int64_t deadline = monotonic_ms() + timeout_ms;
    struct epoll_event events[MAX_EVENTS];
    for (;;) {
        int64_t left = deadline - monotonic_ms();
        int wait = self->nready ? 0 : (left > 0 ? (int)left : 0);
        int n = epoll_wait(self->epoll_fd, events, MAX_EVENTS, wait);
        if (n < 0) {
            if (errno == EINTR) continue;
            self->error = errno;
            return RUN_FAILED;
        }
        int woke = 0;
        pthread_mutex_lock(&self->lock);
        int handed = round_of(self, events, n, &woke);
        pthread_mutex_unlock(&self->lock);
        if (handed) return RUN_HANDED;
        if (woke) return RUN_WAKE;
        if (monotonic_ms() >= deadline) return RUN_TIMEOUT; /* a backlog stays queued */
    }
}

/* ---- Python ------------------------------------------------------------------------------------ */

static int usable(RosLoopObject *self) {
    if (self->initialised) return 1;
    PyErr_SetString(PyExc_RuntimeError, "the RosLoop is not initialised (call __init__)");
    return 0;
}

/* The lock, taken without holding the GIL: a round holds it for a while. */
static void lock_released(RosLoopObject *self) {
    Py_BEGIN_ALLOW_THREADS;
    pthread_mutex_lock(&self->lock);
    Py_END_ALLOW_THREADS;
}

static PyObject *ros_loop_new(PyTypeObject *type, PyObject *args, PyObject *kwds) {
    RosLoopObject *self = (RosLoopObject *)type->tp_alloc(type, 0);
    if (self != NULL) self->epoll_fd = self->wake_fd = -1;
    (void)args;
    (void)kwds;
    return (PyObject *)self;
}

static int ros_loop_init(RosLoopObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "", keywords)) return -1;
    if (self->epoll_fd >= 0) {
        PyErr_SetString(PyExc_RuntimeError, "a RosLoop is initialised once");
        return -1;
    }
    self->epoll_fd = epoll_create1(EPOLL_CLOEXEC);
    if (self->epoll_fd < 0) {
        PyErr_SetFromErrno(PyExc_OSError);
        return -1;
    }
    self->wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    struct epoll_event event = {.events = EPOLLIN, .data.u64 = WAKE_TOKEN};
    if (self->wake_fd < 0 || epoll_ctl(self->epoll_fd, EPOLL_CTL_ADD, self->wake_fd, &event) < 0) {
        PyErr_SetFromErrno(PyExc_OSError);
        return -1;
    }
    if (pthread_mutex_init(&self->lock, NULL) != 0) {
        PyErr_SetString(PyExc_OSError, "cannot create the loop's mutex");
        return -1;
    }
    self->initialised = 1;
    return 0;
}

static void ros_loop_dealloc(RosLoopObject *self) {
    for (int i = 0; i < self->nslots; i++)
        if (self->slots[i] != NULL) {
            ros_pump_clear_callback(self->slots[i]);
            self->slots[i]->attached = 0;
            Py_DECREF(self->slots[i]);
        }
    free(self->slots);
    free(self->generations);
    free(self->ready);
    free(self->moved);
    if (self->initialised) pthread_mutex_destroy(&self->lock);
    if (self->wake_fd >= 0) close(self->wake_fd);
    if (self->epoll_fd >= 0) close(self->epoll_fd);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* A free slot, the tables grown if need be (under the lock); -1 when out of memory. */
static int free_slot(RosLoopObject *self) {
    for (int i = 0; i < self->nslots; i++)
        if (self->slots[i] == NULL) return i;
    int cap = self->nslots ? self->nslots * 2 : 16;
    RosPumpObject **slots = realloc(self->slots, (size_t)cap * sizeof *slots);
    if (slots == NULL) return -1;
    self->slots = slots;
    uint32_t *generations = realloc(self->generations, (size_t)cap * sizeof *generations);
    if (generations == NULL) return -1;
    self->generations = generations;
    int *ready = realloc(self->ready, (size_t)cap * sizeof *ready);
    if (ready == NULL) return -1;
    self->ready = ready;
    int *moved = realloc(self->moved, (size_t)cap * sizeof *moved);
    if (moved == NULL) return -1;
    self->moved = moved;
    for (int i = self->nslots; i < cap; i++) {
        self->slots[i] = NULL;
        self->generations[i] = 0;
    }
    int slot = self->nslots;
    self->nslots = cap;
    return slot;
}

/* add(pump): the loop serves it from now on (rcl's callback is set here). */
static PyObject *ros_loop_add(RosLoopObject *self, PyObject *object) {
    if (!usable(self)) return NULL;
    if (!ros_pump_check(object)) {
        PyErr_SetString(PyExc_TypeError, "add(pump): an initialised RosPump");
        return NULL;
    }
    RosPumpObject *pump = (RosPumpObject *)object;
    if (pump->attached || pump->event_fd < 0) {
        PyErr_SetString(PyExc_ValueError, "the RosPump is attached to a loop already, or has no eventfd");
        return NULL;
    }
    lock_released(self);
    const char *why = NULL;
    int error = 0;
    int slot = free_slot(self);
    if (slot < 0) {
        why = "out of memory";
    } else {
        pump->slot = slot;
        struct epoll_event event = {.events = EPOLLIN, .data.u64 = token_of(self, slot)};
        if (epoll_ctl(self->epoll_fd, EPOLL_CTL_ADD, pump->event_fd, &event) < 0) {
            error = errno;
            why = "epoll refused the channel's eventfd";
        } else if (ros_pump_set_callback(pump) < 0) {
            epoll_ctl(self->epoll_fd, EPOLL_CTL_DEL, pump->event_fd, NULL);
            why = "rcl refused the on-new-message callback";
        } else {
            Py_INCREF(pump); /* with the lock held, but INCREF needs only the GIL we hold */
            self->slots[slot] = pump;
            pump->attached = 1;
            pump->failure = 0;
            queue(self, pump); /* what came before the callback was set */
        }
    }
    pthread_mutex_unlock(&self->lock);
    if (why != NULL) {
        if (error) PyErr_Format(PyExc_OSError, "%s: %s", why, strerror(error));
        else PyErr_SetString(PyExc_RuntimeError, why);
        return NULL;
    }
    uint64_t one = 1; /* a round sooner than the timeout */
    ssize_t written = write(self->wake_fd, &one, sizeof one);
    (void)written;
    Py_RETURN_NONE;
}

/* remove(pump): after it returns, no round touches the pump; rcl's callback is cleared, its
 * messages left to Python are dropped. False if it was not attached. */
static PyObject *ros_loop_remove(RosLoopObject *self, PyObject *object) {
    if (!usable(self)) return NULL;
    if (!ros_pump_check(object)) {
        PyErr_SetString(PyExc_TypeError, "remove(pump): an initialised RosPump");
        return NULL;
    }
    RosPumpObject *pump = (RosPumpObject *)object;
    lock_released(self);
    int slot = pump->slot;
    int attached = pump->attached && slot >= 0 && slot < self->nslots && self->slots[slot] == pump;
    if (attached) {
        epoll_ctl(self->epoll_fd, EPOLL_CTL_DEL, pump->event_fd, NULL);
        self->slots[slot] = NULL;
        self->generations[slot]++;
        forget(self->ready, &self->nready, slot);
        forget(self->moved, &self->nmoved, slot);
        pump->attached = pump->queued = pump->moved = 0;
        pump->slot = -1;
    }
    pthread_mutex_unlock(&self->lock);
    if (!attached) Py_RETURN_FALSE;
    ros_pump_clear_callback(pump);
    ros_pump_clear_refused(pump);
    Py_DECREF(pump);
    Py_RETURN_TRUE;
}

/* run(timeout_ms) -> (status, [(pump, refused CDR messages, failure errno)]): one run of the
 * loop (GIL released) and what moved. status: 0 timeout, 1 woken, 2 something for Python; an
 * OSError if epoll itself failed. */
static PyObject *ros_loop_run(RosLoopObject *self, PyObject *arg) {
    if (!usable(self)) return NULL;
    long timeout_ms = PyLong_AsLong(arg);
    if (timeout_ms == -1 && PyErr_Occurred()) return NULL;
    if (self->running) {
        PyErr_SetString(PyExc_RuntimeError, "the loop runs already");
        return NULL;
    }
    self->running = 1;
    int status;
    Py_BEGIN_ALLOW_THREADS;
    status = loop(self, timeout_ms < 0 ? 0 : timeout_ms);
    pthread_mutex_lock(&self->lock);
    Py_END_ALLOW_THREADS;
    /* The lock is held from here (remove and add wait for it without the GIL). */
    self->running = 0;
    PyObject *moved = PyList_New(0);
    for (int i = 0; moved != NULL && i < self->nmoved; i++) {
        RosPumpObject *pump = self->slots[self->moved[i]];
        /* A message whose bytes object cannot be made (no memory) is counted as lost and the
         * others still go; where a list cannot grow, the messages it would carry are counted
         * as lost and MemoryError is raised. */
        PyObject *refused = PyList_New(0);
        if (refused == NULL) pump->lost += pump->nrefused;
        for (size_t k = 0; refused != NULL && k < pump->nrefused; k++) {
            PyObject *cdr = PyBytes_FromStringAndSize((char *)pump->refused[k],
                                                      (Py_ssize_t)pump->refused_len[k]);
            if (cdr == NULL) {
                PyErr_Clear();
                pump->lost++;
                continue;
            }
            if (PyList_Append(refused, cdr) < 0) {
                pump->lost += pump->nrefused - k + (size_t)PyList_GET_SIZE(refused);
                Py_CLEAR(refused);
            }
            Py_DECREF(cdr);
        }
        size_t carried = refused == NULL ? 0 : (size_t)PyList_GET_SIZE(refused);
        PyObject *item = refused == NULL ? NULL : Py_BuildValue("(ONi)", pump, refused, pump->failure);
        if (item == NULL || PyList_Append(moved, item) < 0) {
            pump->lost += carried;
            Py_CLEAR(moved);
        }
        Py_XDECREF(item);
        ros_pump_clear_refused(pump);
        pump->moved = 0;
    }
    self->nmoved = 0;
    int error = self->error;
    self->error = 0;
    pthread_mutex_unlock(&self->lock);
    if (moved == NULL) return NULL;
    if (error) {
        Py_DECREF(moved);
        errno = error;
        return PyErr_SetFromErrno(PyExc_OSError);
    }
    return Py_BuildValue("(iN)", status, moved);
}

/* wake(): end the current run soon (any thread, GIL or not). */
static PyObject *ros_loop_wake(RosLoopObject *self, PyObject *unused) {
    (void)unused;
    if (!usable(self)) return NULL;
    uint64_t one = 1;
    ssize_t written = write(self->wake_fd, &one, sizeof one);
    (void)written; /* a full counter still wakes the loop */
    Py_RETURN_NONE;
}

static PyObject *ros_loop_size(RosLoopObject *self, PyObject *unused) {
    (void)unused;
    if (!usable(self)) return NULL;
    lock_released(self);
    int count = 0;
    for (int i = 0; i < self->nslots; i++) count += self->slots[i] != NULL;
    pthread_mutex_unlock(&self->lock);
    return PyLong_FromLong(count);
}

static PyMethodDef ros_loop_methods[] = {
    {"add", (PyCFunction)ros_loop_add, METH_O, "add(pump): serve this channel"},
    {"remove", (PyCFunction)ros_loop_remove, METH_O,
     "remove(pump) -> bool: no round touches it after this returns"},
    {"run", (PyCFunction)ros_loop_run, METH_O,
     "run(timeout_ms) -> (status, [(pump, refused, failure)]), the GIL released"},
    {"wake", (PyCFunction)ros_loop_wake, METH_NOARGS, "end the current run soon"},
    {"size", (PyCFunction)ros_loop_size, METH_NOARGS, "how many channels are attached"},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject RosLoopType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.RosLoop",
    .tp_basicsize = sizeof(RosLoopObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The loop of every native ROS -> Gazebo channel (docs/native.md §7).",
    .tp_new = ros_loop_new,
    .tp_init = (initproc)ros_loop_init,
    .tp_dealloc = (destructor)ros_loop_dealloc,
    .tp_methods = ros_loop_methods,
};

int ros_loop_register(PyObject *module) {
    if (PyType_Ready(&RosLoopType) < 0) return -1;
    Py_INCREF(&RosLoopType);
    if (PyModule_AddObject(module, "RosLoop", (PyObject *)&RosLoopType) < 0) {
        Py_DECREF(&RosLoopType);
        return -1;
    }
    return 0;
}
