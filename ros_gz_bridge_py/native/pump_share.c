/* One SUB socket for several Gazebo -> ROS channels (docs/native.md §5): a Pump made with no
 * publisher and no program reads the socket for its peers, the channels' Pumps (`share`),
 * each message into the queue of its topic's peer, and delivers their queues in its turns
 * (pump_loop.c). Python changes the peers only while the reader is out of its loop
 * (native/socket_reader.py), and a peer is as usable as its reader (pump.c pump_usable). */
#include "_native.h"

#include <string.h>

/* Lets go of the peers (they read nothing until they are given a socket or a reader). */
void pump_release_peers(PumpObject *self) {
    for (size_t i = 0; i < self->peer_slots; i++)
        if (self->peers[i] != NULL) {
            self->peers[i]->reader = NULL;
            self->peers[i]->is_due = 0;
        }
    free(self->peers);
    free(self->due);
    self->peers = self->due = NULL;
    self->peer_slots = self->npeers = self->ndue = 0;
    Py_CLEAR(self->peer_objects);
}

/* Whether `pump` may be a peer of `self`: an initialised Pump out of any loop, neither read
 * for by another nor reading for others, with a topic of its own. */
static int peer_usable(PumpObject *self, PyObject *object) {
    if (!PyObject_TypeCheck(object, &rgb_PumpType)) {
        PyErr_SetString(PyExc_TypeError, "share: the peers are Pumps");
        return -1;
    }
    PumpObject *peer = (PumpObject *)object;
    if (pump_usable(peer, 0) < 0) return -1;
    if (peer == self || peer->member.running != NULL || peer->npeers ||
        (peer->reader != NULL && peer->reader != self)) {
        PyErr_SetString(PyExc_ValueError,
                        "share: a peer is this pump, in a loop, or reads for or is read by another");
        return -1;
    }
    return 0;
}

/* share(peers): this pump's socket carries the peers' topics (a sequence of Pumps, each topic
 * once; none: it reads for none, and takes every message itself); only out of a loop. A pump
 * that reads for peers takes no message of its own. */
PyObject *pump_share(PumpObject *self, PyObject *arg) {
    if (pump_out_of_loop(self, "share") < 0) return NULL;
    PyObject *peers = PySequence_Tuple(arg);
    if (peers == NULL) return NULL;
    size_t n = (size_t)PyTuple_GET_SIZE(peers), slots = n ? 2 : 0;
    while (slots && slots < 2 * n) slots *= 2;
    PumpObject **table = slots ? calloc(slots, sizeof *table) : NULL;
    PumpObject **due = n ? calloc(2 * n, sizeof *due) : NULL;
    if (n && (table == NULL || due == NULL)) {
        PyErr_NoMemory();
        goto failed;
    }
    for (size_t k = 0; k < n; k++) {
        PyObject *object = PyTuple_GET_ITEM(peers, (Py_ssize_t)k);
        if (peer_usable(self, object) < 0) goto failed;
        PumpObject *peer = (PumpObject *)object;
        size_t i = pump_topic_hash(peer->topic, peer->topic_len) & (slots - 1);
        for (; table[i] != NULL; i = (i + 1) & (slots - 1))
            if (table[i]->topic_len == peer->topic_len &&
                !memcmp(table[i]->topic, peer->topic, peer->topic_len))
                break;
        if (table[i] != NULL) {
            PyErr_SetString(PyExc_ValueError, "share: a topic is read once");
            goto failed;
        }
        table[i] = peer;
    }
    pump_release_peers(self);
    self->peers = table;
    self->due = due;
    self->peer_slots = slots;
    self->npeers = n;
    self->peer_objects = peers;
    for (size_t i = 0; i < slots; i++) {
        PumpObject *peer = table[i];
        if (peer == NULL) continue;
        peer->reader = self;
        if (peer->count || peer->nhanded || peer->grown) { /* what it kept meanwhile */
            peer->is_due = 1;
            due[self->ndue++] = peer;
        }
    }
    Py_RETURN_NONE;
failed:
    free(table);
    free(due);
    Py_DECREF(peers);
    return NULL;
}
