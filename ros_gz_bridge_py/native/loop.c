/* Loop: the one loop design, run once per direction (docs/native.md §5).
 *
 * A Loop runs every member of its direction (Gazebo -> ROS: each channel's Pump, pump_loop.c;
 * ROS -> Gazebo: each channel's RosPump, ros_pump_loop.c) on one thread, whatever their number, so
 * that a fleet of robots costs no thread per topic and a message no thread switch of its own.
 * The directions differ only in their members' hooks (struct rgb_hooks, _native.h): which
 * descriptors to sleep on, and what one turn does.
 *
 * `run` sleeps in one epoll(7) over every member's descriptors and the loop's own wake-up
 * eventfd, with the GIL released. A member whose descriptor fired becomes fresh; one with more
 * to do at once after its turn (RGB_AGAIN: a socket not read empty yet, messages queued, a
 * whole budget taken) has a backlog, and the loop polls the descriptors without sleeping. Each
 * turn is within the budget (struct rgb_budget: messages and time). A pass turns every fresh
 * member first, in the order they fired, then the backlog in turn, round robin, for at most
 * one slice of the budget before the descriptors are polled again: a message of a quiet topic
 * (/clock beside a hundred busy ones) waits for at most about one slice and one turn, never
 * for a pass over every backlog, and goes out alone, not in a burst with those that came
 * after it (a keep-last-10 subscriber would lose the burst's oldest).
 *
 * `run` returns to Python with the members that need it (what their turns reported: messages
 * handed back, a connection monitor event, a socket or eventfd that cannot be used any more:
 * that member is slept on no more), when `wake` was called (from any thread), or at the
 * timeout. `moved` says which members took messages since it was last called. Python's share
 * of a member may touch its sockets (connects, disconnects): the members it turned are named in
 * the next `run` (`touched`) and get a turn before the loop sleeps.
 *
 * Members join and leave from any thread (`add`, `remove`). Passes run under the loop's mutex,
 * which `add` and `remove` take too, and epoll names a member by its slot and a generation, so
 * once `remove` returns no pass touches the member and no event read before can reach it: its
 * socket or subscription may go. While the loop runs, a member refuses Python calls that would
 * change what a pass reads (rgb_member_usable). */
#include "_native.h"

#include <errno.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#define MAX_EVENTS 64
/* The epoll token of the wake-up eventfd; a member's is its generation, slot and descriptor. */
#define WAKE_TOKEN UINT64_MAX

struct slot {
    PyObject *object; /* the member, a strong reference; NULL: the slot is free */
    struct rgb_member *m;
    uint32_t generation;
    int fds[RGB_MAX_FDS], nfds;
    unsigned fired;          /* its descriptors that fired since its last turn */
    int active, reported, events;
    unsigned long long seen; /* its progress at the last `moved` */
};

typedef struct {
    PyObject_HEAD
    int epoll_fd, wake_fd; /* -1 until __init__ */
    pthread_mutex_t lock;
    atomic_int running, woken;
    struct rgb_budget budget;
    struct slot *slots;
    int nslots, members;
    int *fresh, nfresh;     /* slots whose descriptors fired, in that order: turned first */
    int *active, nactive;   /* slots with a backlog, in the order of their next turn */
    int *scratch;           /* a pass's reordering of `active` */
    int *report, nreport; /* slots with events for Python */
} LoopObject;

static uint64_t token_of(const LoopObject *self, int slot, int fd) {
    return (uint64_t)self->slots[slot].generation << 32 | (uint64_t)slot << 2 | (uint64_t)fd;
}

static void activate(LoopObject *self, int slot) {
    if (!self->slots[slot].active) {
        self->slots[slot].active = 1;
        self->fresh[self->nfresh++] = slot;
    }
}

static void unlist(int *list, int *n, int slot) {
    for (int i = 0; i < *n; i++)
        if (list[i] == slot) {
            memmove(&list[i], &list[i + 1], (size_t)(*n - i - 1) * sizeof *list);
            (*n)--;
            return;
        }
}

/* Sleeps on the member's descriptors no more. */
static void mute(LoopObject *self, struct slot *s) {
    for (int i = 0; i < s->nfds; i++) epoll_ctl(self->epoll_fd, EPOLL_CTL_DEL, s->fds[i], NULL);
    s->nfds = 0;
}

static void drain(int fd) {
    uint64_t count;
    ssize_t ignored = read(fd, &count, sizeof count);
    (void)ignored;
}

static void nudge(LoopObject *self) {
    uint64_t one = 1;
    ssize_t ignored = write(self->wake_fd, &one, sizeof one);
    (void)ignored; /* a full counter still wakes the loop */
}

/* One turn of the member in `index`: 1 when it has more to do at once (it stays active). */
static int turn(LoopObject *self, int index) {
    struct slot *s = &self->slots[index];
    unsigned fired = s->fired;
    s->fired = 0;
    int result = s->m->hooks->turn(s->m, fired, &self->budget);
    int events = result & (RGB_EVENT_HANDED | RGB_EVENT_MONITOR | RGB_EVENT_BROKEN);
    if (events) {
        s->events |= events;
        if (!s->reported) self->report[self->nreport++] = index;
        s->reported = 1;
    }
    if (events & RGB_EVENT_BROKEN) mute(self, s);
    if ((result & RGB_AGAIN) && !(events & RGB_EVENT_BROKEN)) return 1;
    s->active = 0;
    return 0;
}

/* One pass, under the lock: the fresh members, then the backlog for one slice (at least one
 * turn). The backlog's next order: those not reached, those turned, then the fresh ones that
 * have a backlog now. */
static void pass(LoopObject *self) {
    int n = 0, reached = 0;
    for (int i = 0; i < self->nfresh; i++)
        if (turn(self, self->fresh[i])) self->fresh[n++] = self->fresh[i];
    int backlogged = n;
    self->nfresh = 0;
    int64_t end = rgb_now_ns(CLOCK_MONOTONIC) + self->budget.slice_ns;
    int turned = 0;
    while (reached < self->nactive &&
           (reached == 0 || rgb_now_ns(CLOCK_MONOTONIC) < end)) {
        int index = self->active[reached++];
        if (turn(self, index)) self->scratch[turned++] = index;
    }
    int rest = self->nactive - reached;
    memmove(self->active, self->active + reached, (size_t)rest * sizeof *self->active);
    memcpy(self->active + rest, self->scratch, (size_t)turned * sizeof *self->active);
    memcpy(self->active + rest + turned, self->fresh, (size_t)backlogged * sizeof *self->active);
    self->nactive = rest + turned + backlogged;
}

/* Runs until something is reported, `wake` is called or `deadline` passes: 1 when woken. An
 * epoll failure ends it with the errno in *error. */
static int loop_run(LoopObject *self, int64_t deadline, int *error) {
    struct epoll_event events[MAX_EVENTS];
    for (;;) {
        if (atomic_exchange(&self->woken, 0)) return 1;
        pthread_mutex_lock(&self->lock);
        pass(self);
        int reported = self->nreport, active = self->nactive + self->nfresh;
        pthread_mutex_unlock(&self->lock);
        if (reported) return 0;
        int64_t left = deadline - rgb_now_ns(CLOCK_MONOTONIC);
        if (left <= 0) return 0; /* also under a flood: Python's share is due */
        int wait = active ? 0 : (int)((left + 999999) / 1000000);
        int n = epoll_wait(self->epoll_fd, events, MAX_EVENTS, wait);
        if (n < 0 && errno != EINTR) {
            *error = errno;
            return 0;
        }
        pthread_mutex_lock(&self->lock);
        for (int i = 0; i < n; i++) {
            uint64_t token = events[i].data.u64;
            if (token == WAKE_TOKEN) {
                drain(self->wake_fd); /* `woken` says whether it was a wake */
                continue;
            }
            int index = (int)((uint32_t)token >> 2);
            struct slot *s = index < self->nslots ? &self->slots[index] : NULL;
            if (s == NULL || s->object == NULL || (int)(token & 3) >= s->nfds ||
                token_of(self, index, (int)(token & 3)) != token)
                continue; /* it left, or was muted, meanwhile */
            s->fired |= events[i].events & (EPOLLERR | EPOLLHUP) ? RGB_FIRED_ERROR : 1u << (token & 3);
            activate(self, index);
        }
        pthread_mutex_unlock(&self->lock);
    }
}

/* ---- Python ------------------------------------------------------------------------------- */

static int usable(LoopObject *self) {
    if (self->epoll_fd >= 0) return 1;
    PyErr_SetString(PyExc_RuntimeError, "the Loop is not initialised (call __init__)");
    return 0;
}

/* The lock, taken without holding the GIL: a pass holds it for a while. */
static void lock_released(LoopObject *self) {
    Py_BEGIN_ALLOW_THREADS;
    pthread_mutex_lock(&self->lock);
    Py_END_ALLOW_THREADS;
}

/* The slot holding `object`, or -1. */
static int slot_of(LoopObject *self, PyObject *object) {
    struct rgb_member *m = rgb_member_of(object);
    if (m == NULL || m->running != &self->running) return -1;
    return m->slot >= 0 && m->slot < self->nslots && self->slots[m->slot].object == object ? m->slot
                                                                                            : -1;
}

static PyObject *loop_new(PyTypeObject *type, PyObject *args, PyObject *kwds) {
    LoopObject *self = (LoopObject *)type->tp_alloc(type, 0);
    (void)args;
    (void)kwds;
    if (self != NULL) {
        self->epoll_fd = self->wake_fd = -1;
        pthread_mutex_init(&self->lock, NULL);
    }
    return (PyObject *)self;
}

/* Loop(messages, slice_ns): a loop whose members each get at most `messages` messages and
 * `slice_ns` nanoseconds a turn. */
static int loop_init(LoopObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {"messages", "slice_ns", NULL};
    int messages;
    long long slice_ns;
    if (self->epoll_fd >= 0) {
        PyErr_SetString(PyExc_RuntimeError, "a Loop is initialised once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "iL", keywords, &messages, &slice_ns)) return -1;
    if (messages < 1 || slice_ns < 1) {
        PyErr_SetString(PyExc_ValueError, "a budget of at least one message and one nanosecond");
        return -1;
    }
    self->budget = (struct rgb_budget){messages, slice_ns};
    int epoll_fd = epoll_create1(EPOLL_CLOEXEC);
    self->wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    struct epoll_event wake = {.events = EPOLLIN, .data.u64 = WAKE_TOKEN};
    if (epoll_fd < 0 || self->wake_fd < 0 ||
        epoll_ctl(epoll_fd, EPOLL_CTL_ADD, self->wake_fd, &wake) < 0) {
        PyErr_SetFromErrno(PyExc_OSError);
        if (epoll_fd >= 0) close(epoll_fd);
        return -1;
    }
    self->epoll_fd = epoll_fd; /* last: a Loop with an epoll fd is whole */
    return 0;
}

/* Takes the member in `s` out (under the lock); the caller drops the reference. */
static void release(LoopObject *self, struct slot *s) {
    mute(self, s);
    s->m->hooks->detach(s->m);
    s->m->running = NULL;
    s->m->lock = NULL;
    s->m->slot = -1;
    s->object = NULL;
    s->generation++;
    s->fired = 0;
    s->active = s->reported = s->events = 0;
    self->members--;
}

static void loop_dealloc(LoopObject *self) {
    for (int i = 0; i < self->nslots; i++) {
        PyObject *object = self->slots[i].object;
        if (object != NULL) {
            release(self, &self->slots[i]);
            Py_DECREF(object);
        }
    }
    free(self->slots);
    free(self->fresh);
    free(self->active);
    free(self->scratch);
    free(self->report);
    if (self->wake_fd >= 0) close(self->wake_fd);
    if (self->epoll_fd >= 0) close(self->epoll_fd);
    pthread_mutex_destroy(&self->lock);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* A free slot, the tables grown if need be (under the lock); -1 when out of memory. */
static int free_slot(LoopObject *self) {
    for (int i = 0; i < self->nslots; i++)
        if (self->slots[i].object == NULL) return i;
    int cap = self->nslots ? self->nslots * 2 : 16;
    struct slot *slots = realloc(self->slots, (size_t)cap * sizeof *slots);
    if (slots == NULL) return -1;
    self->slots = slots;
    memset(slots + self->nslots, 0, (size_t)(cap - self->nslots) * sizeof *slots);
    int **lists[] = {&self->fresh, &self->active, &self->scratch, &self->report};
    for (size_t i = 0; i < sizeof lists / sizeof *lists; i++) {
        int *grown = realloc(*lists[i], (size_t)cap * sizeof *grown);
        if (grown == NULL) return -1;
        *lists[i] = grown;
    }
    int slot = self->nslots;
    self->nslots = cap;
    return slot;
}

/* add(member): the loop runs it from now on (any thread). */
static PyObject *loop_add(LoopObject *self, PyObject *object) {
    if (!usable(self)) return NULL;
    struct rgb_member *m = rgb_member_of(object);
    if (m == NULL) {
        PyErr_SetString(PyExc_TypeError, "add(member): an initialised Pump or RosPump");
        return NULL;
    }
    const char *why = NULL;
    int error = 0;
    lock_released(self);
    int index = m->running != NULL ? -1 : free_slot(self);
    struct slot *s = index < 0 ? NULL : &self->slots[index];
    if (m->running != NULL) {
        why = "the member is in a loop already";
    } else if (s == NULL) {
        why = "out of memory";
    } else {
        int n = m->hooks->descriptors(m, s->fds, &why);
        for (s->nfds = 0; s->nfds < n; s->nfds++) {
            struct epoll_event event = {.events = EPOLLIN, .data.u64 = token_of(self, index, s->nfds)};
            if (epoll_ctl(self->epoll_fd, EPOLL_CTL_ADD, s->fds[s->nfds], &event) < 0) {
                error = errno;
                why = "epoll refused the member's descriptor";
                break;
            }
        }
        if (why == NULL && m->hooks->attach(m, &why) == 0) {
            s->object = Py_NewRef(object);
            s->m = m;
            s->fired = (1u << s->nfds) - 1; /* what came before it joined */
            s->seen = m->hooks->progress(m);
            m->running = &self->running;
            m->lock = &self->lock;
            m->slot = index;
            self->members++;
            activate(self, index);
        } else {
            mute(self, s);
        }
    }
    pthread_mutex_unlock(&self->lock);
    if (why != NULL) {
        if (error) PyErr_Format(PyExc_OSError, "%s: %s", why, strerror(error));
        else PyErr_SetString(PyExc_RuntimeError, why);
        return NULL;
    }
    nudge(self); /* a pass sooner than the timeout */
    Py_RETURN_NONE;
}

/* remove(member) -> bool: once it returns, no pass touches the member (any thread); False if
 * it was not in this loop. */
static PyObject *loop_remove(LoopObject *self, PyObject *object) {
    if (!usable(self)) return NULL;
    if (rgb_member_of(object) == NULL) {
        PyErr_SetString(PyExc_TypeError, "remove(member): an initialised Pump or RosPump");
        return NULL;
    }
    lock_released(self);
    int index = slot_of(self, object);
    if (index >= 0) {
        struct slot *s = &self->slots[index];
        if (s->active) {
            unlist(self->fresh, &self->nfresh, index);
            unlist(self->active, &self->nactive, index);
        }
        if (s->reported) unlist(self->report, &self->nreport, index);
        release(self, s);
    }
    pthread_mutex_unlock(&self->lock);
    if (index < 0) Py_RETURN_FALSE;
    Py_DECREF(object);
    Py_RETURN_TRUE;
}

/* run(timeout_ms, touched) -> (woken, [(member, events)]), the GIL released; touched: the
 * members Python turned since the last run (their turn comes before the loop sleeps). */
static PyObject *loop_run_method(LoopObject *self, PyObject *args) {
    long timeout_ms;
    PyObject *touched;
    if (!usable(self) || !PyArg_ParseTuple(args, "lO", &timeout_ms, &touched)) return NULL;
    if (atomic_load(&self->running)) {
        PyErr_SetString(PyExc_RuntimeError, "the Loop runs already");
        return NULL;
    }
    PyObject *sequence = PySequence_Fast(touched, "touched must be a sequence");
    if (sequence == NULL) return NULL;
    lock_released(self);
    for (Py_ssize_t i = 0; i < PySequence_Fast_GET_SIZE(sequence); i++) {
        int index = slot_of(self, PySequence_Fast_GET_ITEM(sequence, i));
        if (index >= 0 && self->slots[index].nfds > 0) {
            self->slots[index].fired |= (1u << self->slots[index].nfds) - 1;
            activate(self, index);
        }
    }
    for (int i = 0; i < self->nreport; i++)
        self->slots[self->report[i]].reported = self->slots[self->report[i]].events = 0;
    self->nreport = 0;
    pthread_mutex_unlock(&self->lock);
    Py_DECREF(sequence);
    int64_t deadline = rgb_now_ns(CLOCK_MONOTONIC) + (timeout_ms < 0 ? 0 : timeout_ms) * 1000000LL;
    int woken, error = 0;
    atomic_store(&self->running, 1);
    Py_BEGIN_ALLOW_THREADS;
    woken = loop_run(self, deadline, &error);
    pthread_mutex_lock(&self->lock);
    Py_END_ALLOW_THREADS;
    atomic_store(&self->running, 0);
    PyObject *reported = PyList_New(self->nreport);
    for (int i = 0; reported != NULL && i < self->nreport; i++) {
        const struct slot *s = &self->slots[self->report[i]];
        PyObject *item = Py_BuildValue("(Oi)", s->object, s->events);
        if (item == NULL) Py_CLEAR(reported);
        else PyList_SET_ITEM(reported, i, item);
    }
    pthread_mutex_unlock(&self->lock);
    if (reported == NULL) return NULL;
    if (error) {
        Py_DECREF(reported);
        errno = error;
        return PyErr_SetFromErrno(PyExc_OSError);
    }
    return Py_BuildValue("(NN)", PyBool_FromLong(woken), reported);
}

/* moved() -> [member]: the members that took a message since the last call. */
static PyObject *loop_moved(LoopObject *self, PyObject *unused) {
    (void)unused;
    if (!usable(self)) return NULL;
    PyObject *moved = PyList_New(0);
    lock_released(self);
    for (int i = 0; moved != NULL && i < self->nslots; i++) {
        struct slot *s = &self->slots[i];
        if (s->object == NULL) continue;
        unsigned long long progress = s->m->hooks->progress(s->m);
        if (progress != s->seen && PyList_Append(moved, s->object) < 0) Py_CLEAR(moved);
        s->seen = progress;
    }
    pthread_mutex_unlock(&self->lock);
    return moved;
}

/* wake(): from any thread, makes a run return soon (at once when it sleeps). */
static PyObject *loop_wake(LoopObject *self, PyObject *unused) {
    (void)unused;
    if (!usable(self)) return NULL;
    atomic_store(&self->woken, 1);
    nudge(self);
    Py_RETURN_NONE;
}

static PyObject *loop_size(LoopObject *self, PyObject *unused) {
    (void)unused;
    if (!usable(self)) return NULL;
    lock_released(self);
    int members = self->members;
    pthread_mutex_unlock(&self->lock);
    return PyLong_FromLong(members);
}

static PyMethodDef loop_methods[] = {
    {"add", (PyCFunction)loop_add, METH_O, "add(member): run it from now on (any thread)"},
    {"remove", (PyCFunction)loop_remove, METH_O,
     "remove(member) -> bool: no pass touches it once this returns (any thread)"},
    {"run", (PyCFunction)loop_run_method, METH_VARARGS,
     "run(timeout_ms, touched) -> (woken, [(member, events)]), the GIL released"},
    {"moved", (PyCFunction)loop_moved, METH_NOARGS,
     "moved() -> [member]: the members that took a message since the last call"},
    {"wake", (PyCFunction)loop_wake, METH_NOARGS, "wake(): a run returns soon (any thread)"},
    {"size", (PyCFunction)loop_size, METH_NOARGS, "size() -> the number of members"},
    {NULL, NULL, 0, NULL},
};

PyTypeObject rgb_LoopType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.Loop",
    .tp_basicsize = sizeof(LoopObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The loop of every native channel of one direction (docs/native.md §5).",
    .tp_new = loop_new,
    .tp_init = (initproc)loop_init,
    .tp_dealloc = (destructor)loop_dealloc,
    .tp_methods = loop_methods,
};
