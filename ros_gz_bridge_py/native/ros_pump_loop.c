/* The per-message work of a native ROS -> Gazebo channel (docs/native.md §7), run by its
 * direction's Loop (loop.c) through the hooks at the end, with the GIL released.
 *
 * rcl tells of new messages through the subscription's on-new-message callback (an eventfd,
 * the descriptor the loop sleeps on); a turn takes each message serialized from the rclpy
 * subscription's rcl handle, skips it when one of the bridge's own publishers on the topic
 * wrote it (by publisher GID, as the C++ bridge does), passes it through max_rate, encodes it
 * (encode.c) in each spelling Gazebo subscribers take and sends it as the four data frames on
 * the channel's own ZeroMQ PUB socket. No Python runs per message; what an encoder leaves to
 * Python is handed back (ros_pump.c take_handed). */
#include "_native.h"

#include <errno.h>
#include <string.h>
#include <unistd.h>

enum { RCL_TAKE_FAILED = 401, ZMQ_SNDMORE_ = 2, ZMQ_DONTWAIT_ = 1 };
/* Retries of a frame send that a signal interrupted. */
#define EINTR_RETRIES 8

/* rcl's on-new-message callback, on a middleware thread: wake the loop. */
static void on_new_message(const void *user_data, size_t number_of_events) {
    const RosPumpObject *self = user_data;
    uint64_t n = number_of_events ? number_of_events : 1;
    ssize_t written = write(self->event_fd, &n, sizeof n);
    (void)written; /* a full counter still wakes the loop */
}


static int is_ignored(const RosPumpObject *self, const rmw_gid *gid) {
    for (int i = 0; i < self->nignored; i++)
        if (!memcmp(self->ignored[i], gid->data, GID_SIZE)) return 1;
    return 0;
}

/* Hands a message to Python as a copy. When memory runs out it is counted as lost instead
 * (never handed over empty: an empty payload would be sent as an all-default message). */
static void refuse(RosPumpObject *self, const uint8_t *cdr, size_t len) {
    uint8_t *copy = NULL;
    if (!rgb_reserve(&self->refused, &self->refused_cap, self->nrefused + 1,
                     sizeof *self->refused, 16))
        copy = rgb_copy(cdr, len);
    if (copy == NULL) {
        self->lost++;
        return;
    }
    self->refused[self->nrefused++] = (struct refused){copy, len};
}

void ros_pump_clear_refused(RosPumpObject *self) {
    for (size_t i = 0; i < self->nrefused; i++) free(self->refused[i].cdr);
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
int ros_pump_send_frames(RosPumpObject *self, const struct spelling *s, const struct rgb_out *out) {
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
        if (!ros_pump_send_frames(self, s, &self->out[encoded[i] >= 2 ? encoded[i] - 2 : i])) sent_all = 0;
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

void ros_pump_clear_callback(RosPumpObject *self) {
    if (self->callback_set) {
        self->f.set_callback(self->subscription, NULL, NULL);
        self->f.reset_error();
        self->callback_set = 0;
    }
}

static void detach(struct rgb_member *m) {
    RosPumpObject *self = RGB_OWNER(RosPumpObject, m);
    ros_pump_clear_callback(self);
    ros_pump_clear_refused(self);
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
        } else if (!rgb_admit(&self->next_ns, self->period_ns)) {
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

const struct rgb_hooks rgb_ros_pump_hooks = {descriptors, attach, detach, turn, progress};
