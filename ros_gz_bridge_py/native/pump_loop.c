/* The per-message work of a native Gazebo -> ROS channel (docs/native.md §5), run by its
 * direction's Loop (loop.c) through the hooks at the end, with the GIL released.
 *
 * A turn reads each message's four frames from the topic's SUB socket, keeps the newest
 * `capacity` payloads and at most `max_bytes` of them (dropping the oldest, before any work is
 * spent on them), applies max_rate, transcodes each payload with the program of its wire type
 * and publishes it through rcl on the channel's publisher. No Python runs per message. What it
 * does not decide is handed back to Python, which stays the reference (pump.c take_handed):
 * frames of a (sender, type) it has not been told about (Python judges them and tells it with
 * `learn`), and payloads its program does not take (Python converts them, or says why not).
 *
 * ZMQ_FD is edge-like: readable while libzmq has commands to process, and a recv that returns
 * EAGAIN has processed them all. So a socket is slept on only after a read found it empty;
 * until then the pump is `readable` and its turns ask to come again (RGB_AGAIN). The socket's
 * own ZMQ_EVENTS is never asked: a SUB socket answers it by prefetching a message. */
#include "_native.h"

#include <errno.h>
#include <string.h>

enum { ZMQ_POLLIN_ = 1, ZMQ_DONTWAIT_ = 1, ZMQ_FD_ = 14, ZMQ_EVENTS_ = 15 };

/* ---- publication windows (the loop guard, core/loop_guard.py) ----------------------------- */

/* FNV-1a over a CDR message's body length and the body's first and last DIGEST_ENDS bytes (the
 * whole of a small message; a large one's header and end): another writer's sample with our
 * sequence number, written during our publish call, is told from ours by it. Never 0 (not
 * known). The body is what follows the 4-byte encapsulation header, less a middleware's
 * padding to a multiple of 4: the count in the options' last two bits (XTypes; CycloneDDS),
 * then trailing zero bytes (older Fast DDS), as core/loop_guard.py's _ends takes it. */
enum { DIGEST_ENDS = 256 };

static uint64_t fnv1a(uint64_t hash, const uint8_t *data, size_t len) {
    for (size_t i = 0; i < len; i++) hash = (hash ^ data[i]) * 0x100000001b3ULL;
    return hash;
}

size_t pump_topic_hash(const uint8_t *topic, size_t len) {
    return (size_t)fnv1a(0xcbf29ce484222325ULL, topic, len);
}

uint64_t rgb_cdr_digest(const uint8_t *cdr, size_t len) {
    if (len >= 4) {
        size_t pad = cdr[3] & 3u;
        len = len - 4 > pad ? len - 4 - pad : 0;
        cdr += 4;
    }
    while (len && cdr[len - 1] == 0) len--;
    uint8_t length[8];
    for (int i = 0; i < 8; i++) length[i] = (uint8_t)((uint64_t)len >> (8 * i));
    size_t ends = len < DIGEST_ENDS ? len : DIGEST_ENDS;
    uint64_t hash = fnv1a(0xcbf29ce484222325ULL, length, sizeof length);
    if (ends) hash = fnv1a(fnv1a(hash, cdr, ends), cdr + (len - ends), ends);
    return hash ? hash : 1;
}

uint64_t pump_begin_publication(PumpObject *self, uint64_t digest) {
    pthread_mutex_lock(&self->lock);
    uint64_t sequence = ++self->sequence;
    struct window *w = &self->windows[sequence % PUMP_HISTORY];
    w->sequence = sequence;
    w->start = rgb_now_ns(CLOCK_REALTIME);
    w->end = INT64_MAX;
    w->digest = digest;
    pthread_mutex_unlock(&self->lock);
    return sequence;
}

void pump_end_publication(PumpObject *self, uint64_t sequence, int ok, uint64_t digest) {
    pthread_mutex_lock(&self->lock);
    struct window *w = &self->windows[sequence % PUMP_HISTORY];
    if (!ok) {
        w->sequence = 0;
        if (self->sequence == sequence) self->sequence--;
    } else if (w->sequence == sequence) {
        w->end = rgb_now_ns(CLOCK_REALTIME);
        if (digest) w->digest = digest;
    }
    pthread_mutex_unlock(&self->lock);
}

/* ---- the queue and the hand-over ------------------------------------------------------------ */

int pump_find_route(PumpObject *self, const uint8_t *sender, size_t sender_len,
                    const uint8_t *type, size_t type_len) {
    for (int i = 0; i < self->nroutes; i++) {
        struct route *r = &self->routes[i];
        if (r->sender_len == sender_len && r->type_len == type_len &&
            !memcmp(r->sender, sender, sender_len) && !memcmp(r->type, type, type_len))
            return i;
    }
    return -1;
}

void pump_clear_ring(PumpObject *self) {
    while (self->count) {
        self->f.msg_close(&self->ring[self->head].payload);
        self->head = (self->head + 1) % self->capacity;
        self->count--;
    }
    self->queued_bytes = 0;
}

void pump_clear_handover(PumpObject *self) {
    for (size_t i = 0; i < self->nhanded; i++)
        for (int k = 0; k < self->handover[i].nframes; k++) free(self->handover[i].data[k]);
    self->nhanded = 0;
    self->handed_bytes = 0;
}

/* A new entry of the hand-over (NULL, counted as lost, when memory runs out). */
static struct handed *hand(PumpObject *self, int kind, int route, int status) {
    if (rgb_reserve(&self->handover, &self->handed_cap, self->nhanded + 1,
                    sizeof *self->handover, 16)) {
        self->lost++;
        return NULL;
    }
    struct handed *h = &self->handover[self->nhanded++];
    memset(h, 0, sizeof *h);
    h->kind = kind;
    h->route = route;
    h->status = status;
    return h;
}

/* Hands `n` frames to Python as copies. When memory runs out nothing is handed (an empty
 * payload would parse as a valid all-default message) and the message is counted as lost. */
static void hand_frames(PumpObject *self, int kind, int route, int status, zmq_msg *frames,
                        int n) {
    struct handed *h = hand(self, kind, route, status);
    for (int i = 0; h != NULL && i < n; i++) {
        h->size[i] = self->f.msg_size(&frames[i]);
        h->data[i] = rgb_copy(self->f.msg_data(&frames[i]), h->size[i]);
        h->nframes = i + 1;
        if (h->data[i] == NULL) {
            for (int k = 0; k < i; k++) free(h->data[k]);
            self->nhanded--;
            self->lost++;
            return;
        }
    }
    for (int i = 0; h != NULL && i < n; i++) self->handed_bytes += h->size[i];
}

static void drop_oldest(PumpObject *self) {
    struct queued *oldest = &self->ring[self->head];
    const struct route *r = &self->routes[oldest->route];
    self->drop_sender_len = r->sender_len < PUMP_SENDER_MAX ? r->sender_len : PUMP_SENDER_MAX;
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

/* ---- reading ------------------------------------------------------------------------------- */

/* The pump a message of topic frame `topic` is for. A pump that reads for no peer takes
 * every message its socket brings (Python judges what is not its topic's); one that reads
 * for peers, only its peers' topics' (a frame no peer takes is nobody's: ZeroMQ filters by
 * prefix, and lets through other topics that one of ours prefixes). */
static PumpObject *pump_for(PumpObject *self, const uint8_t *topic, size_t len) {
    if (self->peer_slots == 0) return self;
    size_t mask = self->peer_slots - 1;
    for (size_t i = pump_topic_hash(topic, len) & mask;; i = (i + 1) & mask) {
        PumpObject *peer = self->peers[i];
        if (peer == NULL) return NULL;
        if (peer->topic_len == len && !memcmp(peer->topic, topic, len)) return peer;
    }
}

static void make_due(PumpObject *self, PumpObject *peer) {
    if (peer != self && !peer->is_due) {
        peer->is_due = 1;
        self->due[self->ndue++] = peer;
    }
}

/* Reads one message: 1 when one was read, 0 when none was waiting, -1 when the socket cannot
 * be read (its context terminated, or it is closed). `*to` is the pump it was for. */
static int read_message(PumpObject *self, PumpObject **to) {
    zmq_msg frames[PUMP_FRAMES];
    int n = 0, more = 1, extra = 0;
    while (more) {
        zmq_msg scratch, *frame = n < PUMP_FRAMES ? &frames[n] : &scratch;
        self->f.msg_init(frame);
        if (self->f.msg_recv(frame, self->sock, n ? 0 : ZMQ_DONTWAIT_) < 0) {
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
    PumpObject *pump = pump_for(self, self->f.msg_data(&frames[0]), self->f.msg_size(&frames[0]));
    *to = pump;
    if (pump == NULL) { /* another topic's */
        self->skipped++;
        for (int i = 0; i < n; i++) self->f.msg_close(&frames[i]);
        return 1;
    }
    if (pump != self) {
        pump->taken++;
        make_due(self, pump);
    }
    if (n > 2) {
        size_t size = self->f.msg_size(&frames[2]);
        self->bytes_read += size;
        if (pump != self) pump->bytes_read += size;
        if (size > pump->watch_above && size > pump->grown) pump->grown = size;
    }
    int route = -1;
    if (n == 4 && !extra && self->f.msg_size(&frames[0]) == pump->topic_len &&
        !memcmp(self->f.msg_data(&frames[0]), pump->topic, pump->topic_len)) {
        route = pump_find_route(pump, self->f.msg_data(&frames[1]), self->f.msg_size(&frames[1]),
                                self->f.msg_data(&frames[3]), self->f.msg_size(&frames[3]));
        if (route >= 0) pump->routes[route].used = pump->taken;
    }
    if (route >= 0 && pump->routes[route].program >= 0) {
        keep(pump, &frames[2], route);
        self->f.msg_close(&frames[0]);
        self->f.msg_close(&frames[1]);
        self->f.msg_close(&frames[3]);
        return 1;
    }
    if (route >= 0) { /* a spelling already taken from this publisher: not ours */
        pump->skipped++;
    } else {
        hand_frames(pump, HANDED_UNROUTED, -1, 0, frames, n);
    }
    for (int i = 0; i < n; i++) self->f.msg_close(&frames[i]);
    return 1;
}

/* ---- delivering ---------------------------------------------------------------------------- */

static void deliver(PumpObject *self, struct queued *q) {
    self->received++;
    if (!rgb_admit(&self->next_ns, self->period_ns)) {
        self->rate_limited++;
        return;
    }
    int program = self->routes[q->route].program;
    const uint8_t *data = self->f.msg_data(&q->payload);
    size_t size = self->f.msg_size(&q->payload);
    enum rgb_status status =
        rgb_to_cdr(self->programs[program].program, data, size, &self->out, NULL);
    if (status == RGB_OK) {
        /* its allocator left zero: rcl only reads the buffer */
        rcl_bytes message = {self->out.data, self->out.len, self->out.cap, {0}};
        uint64_t digest = __atomic_load_n(&self->guarded, __ATOMIC_RELAXED)
                              ? rgb_cdr_digest(self->out.data, self->out.len)
                              : 0;
        uint64_t sequence = pump_begin_publication(self, digest);
        int ret = self->f.publish(self->publisher, &message, NULL);
        pump_end_publication(self, sequence, ret == 0, 0);
        rgb_trim(&self->out); /* a large message's buffer goes back at once */
        if (ret == 0) {
            self->published++;
            return;
        }
        self->f.reset_error();
        status = RGB_FALLBACK; /* Python publishes it, or says why it cannot */
    }
    if (status != RGB_TOO_LARGE) {
        hand_frames(self, HANDED_REFUSED, q->route, (int)status, &q->payload, 1);
        return;
    }
    struct handed *h = hand(self, HANDED_TOO_LARGE, q->route, status);
    if (h != NULL) { /* the figures Python words the refusal with */
        h->items = self->out.refused.items;
        h->least = self->out.refused.least;
        h->payload_size = size;
    }
}

/* ---- the hooks (loop.c) -------------------------------------------------------------------- */

static int zmq_fd(PumpObject *self, void *sock) {
    int fd = -1;
    size_t size = sizeof fd;
    return self->f.getsockopt(sock, ZMQ_FD_, &fd, &size) == 0 ? fd : -1;
}

static int descriptors(struct rgb_member *m, int fds[RGB_MAX_FDS], const char **why) {
    PumpObject *self = RGB_OWNER(PumpObject, m);
    fds[0] = self->sock == NULL ? -1 : zmq_fd(self, self->sock);
    fds[1] = self->monitor == NULL ? -1 : zmq_fd(self, self->monitor);
    if (fds[0] < 0 || (self->monitor != NULL && fds[1] < 0)) {
        *why = "the pump's socket (read_from) or its monitor has no descriptor to poll";
        return -1;
    }
    return self->monitor == NULL ? 1 : 2;
}

static int attach(struct rgb_member *m, const char **why) {
    (void)why;
    RGB_OWNER(PumpObject, m)->readable = 0; /* the first turn reads it */
    return 0;
}

static void detach(struct rgb_member *m) { (void)m; }

/* Whether the monitor (a PAIR socket: asking ZMQ_EVENTS prefetches nothing) has an event. */
static int monitor_ready(PumpObject *self) {
    int events = 0;
    size_t size = sizeof events;
    return self->f.getsockopt(self->monitor, ZMQ_EVENTS_, &events, &size) == 0 &&
           (events & ZMQ_POLLIN_);
}

/* Delivers `pump`'s queue: at most the budget's messages, and none after `slice_end`. */
static void deliver_queue(PumpObject *pump, const struct rgb_budget *budget, int64_t slice_end) {
    for (int i = 0; i < budget->messages && pump->count; i++) {
        struct queued *q = &pump->ring[pump->head];
        pump->head = (pump->head + 1) % pump->capacity;
        pump->count--;
        pump->queued_bytes -= pump->f.msg_size(&q->payload);
        deliver(pump, q);
        pump->f.msg_close(&q->payload);
        if (rgb_now_ns(CLOCK_MONOTONIC) >= slice_end) break;
    }
}

/* Delivers the queues of the peers that took messages, each within the budget, until the
 * slice ends; the next turn begins with the first not reached. A peer stays due while it has
 * messages queued (RGB_AGAIN) or something for Python (RGB_EVENT_HANDED, at every turn until
 * Python takes it, as a pump's own turns say). */
static int deliver_peers(PumpObject *self, const struct rgb_budget *budget, int64_t slice_end) {
    int events = 0;
    size_t reached = 0, kept = 0;
    if (self->ndue == 0) return 0;
    while (reached < self->ndue && (reached == 0 || rgb_now_ns(CLOCK_MONOTONIC) < slice_end)) {
        PumpObject *peer = self->due[reached++];
        deliver_queue(peer, budget, slice_end);
        if (peer->nhanded || peer->grown) events |= RGB_EVENT_HANDED;
        if (peer->count) events |= RGB_AGAIN;
        if (peer->count || peer->nhanded || peer->grown) self->due[kept++] = peer;
        else peer->is_due = 0;
    }
    if (reached < self->ndue) events |= RGB_AGAIN;
    /* not reached first, then those turned that still have messages */
    size_t rest = self->ndue - reached;
    PumpObject **turned = self->due + self->npeers; /* scratch beyond the live entries */
    memcpy(turned, self->due, kept * sizeof *turned);
    memmove(self->due, self->due + reached, rest * sizeof *self->due);
    memcpy(self->due + rest, turned, kept * sizeof *turned);
    self->ndue = rest + kept;
    return events;
}

/* Reads until the socket is empty or the budget is spent, then delivers. The read also ends
 * early once a payload outgrew the watched size, so the socket's owner replaces the socket
 * before a budget more of them arrive, and once the copies handed to Python hold max_bytes, so
 * that Python learns their route before more are copied: either used to wait for a whole budget
 * of 32 MB messages (2 GB, the loop's other members starved meanwhile). */
static int turn(struct rgb_member *m, unsigned fired, const struct rgb_budget *budget) {
    PumpObject *self = RGB_OWNER(PumpObject, m);
    int events = 0;
    if (fired & RGB_FIRED_ERROR) return RGB_EVENT_BROKEN;
    if ((fired & 2) && monitor_ready(self)) events |= RGB_EVENT_MONITOR;
    if (fired & 1) self->readable = 1;
    for (int i = 0; self->readable && i < budget->messages; i++) {
        PumpObject *to = self;
        int read = read_message(self, &to);
        if (read <= 0) self->readable = 0;
        if (read < 0) events |= RGB_EVENT_BROKEN;
        if (to != NULL && (to->grown || to->handed_bytes >= to->max_bytes)) break;
    }
    int64_t slice_end = rgb_now_ns(CLOCK_MONOTONIC) + budget->slice_ns;
    deliver_queue(self, budget, slice_end);
    events |= deliver_peers(self, budget, slice_end);
    if (self->nhanded || self->grown) events |= RGB_EVENT_HANDED;
    return events | (self->readable || self->count ? RGB_AGAIN : 0);
}

static unsigned long long progress(const struct rgb_member *m) {
    return RGB_OWNER(PumpObject, m)->taken;
}

const struct rgb_hooks rgb_pump_hooks = {descriptors, attach, detach, turn, progress};
