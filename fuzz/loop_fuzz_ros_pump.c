/* The ROS -> Gazebo half of fuzz/loop_fuzz.c: a RosPump (ros_pump.c, ros_pump_loop.c), its
 * fake rcl subscription and ZeroMQ PUB socket, and the model checked against it. */
#include "encoders.h"
#include "loop_fuzz.h"

/* The fake rcl subscription: CDR messages and their publishers, taken in order. */
struct cdr_message {
    uint8_t *data;
    size_t len;
    int publisher; /* 0-7: its GID is GID_OF(publisher) */
};

static struct cdr_message cdr_messages[MAX_MESSAGES];
static int ncdr, next_take, take_error;
static event_callback callback;
static const void *callback_data;
/* The fake PUB socket: call number c fails (errno send_errno) for c in [fail_from, fail_to). */
static long send_calls, fail_from, fail_to;
static int send_errno;
/* Python's sends of one input, at most (each message's are at most 4 spellings' 4 frames) */
#define PYTHON_SENDS 1024
static struct frame sent[4 * (MAX_MESSAGES * MAX_SPELLINGS + PYTHON_SENDS)];
static int sent_more[4 * (MAX_MESSAGES * MAX_SPELLINGS + PYTHON_SENDS)]; /* ZMQ_SNDMORE */
static int nsent, python_sends;

#define GID_BYTE(publisher, k) ((uint8_t)(0x40 + (publisher) * 16 + (k)))

static void *a_allocate(size_t size, void *state) {
    (void)state;
    return malloc(size);
}
static void a_deallocate(void *pointer, void *state) {
    (void)state;
    free(pointer);
}
static void *a_reallocate(void *pointer, size_t size, void *state) {
    (void)state;
    return realloc(pointer, size);
}
static void *a_zero_allocate(size_t count, size_t size, void *state) {
    (void)state;
    return calloc(count, size);
}
static void f_reset_error(void) {}

static rcu_allocator f_default_allocator(void) {
    return (rcu_allocator){a_allocate, a_deallocate, a_reallocate, a_zero_allocate, NULL};
}

static int f_take(const void *subscription, rcl_bytes *message, rmw_info *info, void *allocation) {
    (void)subscription;
    (void)allocation;
    if (take_error) {
        take_error = 0;
        return 1; /* RCL_RET_ERROR */
    }
    if (next_take >= ncdr) return 401; /* RCL_RET_SUBSCRIPTION_TAKE_FAILED */
    const struct cdr_message *m = &cdr_messages[next_take++];
    /* a buffer of exactly the message's length: ASan sees a read past it */
    uint8_t *buffer = message->allocator.reallocate(message->buffer, m->len ? m->len : 1,
                                                    message->allocator.state);
    CHECK(buffer != NULL);
    message->buffer = buffer;
    message->buffer_capacity = m->len ? m->len : 1;
    memcpy(buffer, m->data, m->len);
    message->buffer_length = m->len;
    for (int k = 0; k < GID_SIZE; k++) info->publisher_gid.data[k] = GID_BYTE(m->publisher, k);
    return 0;
}

static int f_set_callback(const void *subscription, event_callback cb, const void *user_data) {
    (void)subscription;
    callback = cb;
    callback_data = user_data;
    return 0;
}

static void *f_publisher_rmw_handle(const void *publisher) {
    return (uintptr_t)publisher % 8 == 7 ? NULL : (void *)publisher; /* 7: no handle */
}

static int f_gid_for_publisher(const void *rmw_publisher, rmw_gid *gid) {
    int publisher = (int)((uintptr_t)rmw_publisher % 8);
    if (publisher == 6) return 1; /* 6: rmw cannot tell its GID */
    for (int k = 0; k < GID_SIZE; k++) gid->data[k] = GID_BYTE(publisher, k);
    return 0;
}

static int f_send(void *socket, const void *buffer, size_t length, int flags) {
    (void)socket;
    CHECK(flags & 1); /* ZMQ_DONTWAIT: a PUB socket is never waited on */
    long call = send_calls++;
    if (call >= fail_from && call < fail_to) {
        errno = send_errno;
        return -1;
    }
    CHECK(nsent < (int)(sizeof sent / sizeof *sent));
    uint8_t *copy = malloc(length ? length : 1);
    CHECK(copy != NULL);
    memcpy(copy, buffer, length);
    sent_more[nsent] = flags & 2 ? 1 : 0;
    sent[nsent++] = (struct frame){copy, length};
    return (int)length;
}

static PyObject *encoders_of[ENCODER_COUNT];
static struct rgb_encoder encoder_models[ENCODER_COUNT];
static int encoders_loaded[ENCODER_COUNT];

static PyObject *encoder_object(int e) {
    if (!encoders_loaded[e]) {
        const char *why = NULL;
        CHECK(rgb_encoder_load(&encoder_models[e], ENCODERS[e].words, ENCODERS[e].len, &why) == 0);
        encoders_of[e] = call(module, "Encoder", "(y#)", (char *)ENCODERS[e].words,
                              (Py_ssize_t)(ENCODERS[e].len * 4));
        encoders_loaded[e] = 1;
    }
    return encoders_of[e];
}

static struct ros_model {
    int nspellings, encoder[MAX_SPELLINGS], active[MAX_SPELLINGS], rate_limited_all, admitted;
    char type[MAX_SPELLINGS][64], topic[MAX_SPELLINGS][64], sender[MAX_SPELLINGS][64];
    int ignored[8]; /* by publisher */
    struct rgb_out out[MAX_SPELLINGS];
    long send_calls;
    int expected_sent, failure;
    int refused[MAX_MESSAGES], nrefused; /* message indices */
    unsigned long long received, own_skipped, rate_limited, published, take_errors,
        send_failures, bytes_read;
} ros;

/* One frame as the pump sends it, in the model: 0, or the errno (EINTR tried 8 times more). */
static int model_send_frame(const void *data, size_t len, int more) {
    for (int attempt = 0;; attempt++) {
        long call = ros.send_calls++;
        if (!(call >= fail_from && call < fail_to)) {
            CHECK(ros.expected_sent < nsent);
            CHECK(sent_more[ros.expected_sent] == more);
            const struct frame *f = &sent[ros.expected_sent++];
            CHECK(f->size == len && (len == 0 || !memcmp(f->data, data, len)));
            return 0;
        }
        if (send_errno != EINTR || attempt == 8) return send_errno;
    }
}

static int model_send_frames(int i, const struct rgb_out *out) {
    int error = model_send_frame(ros.topic[i], strlen(ros.topic[i]), 1);
    if (error) {
        ros.send_failures++;
        if (error != EAGAIN) ros.failure = error;
        return 0;
    }
    error = model_send_frame(ros.sender[i], strlen(ros.sender[i]), 1);
    if (!error) error = model_send_frame(out->data, out->len, 1);
    if (!error) error = model_send_frame(ros.type[i], strlen(ros.type[i]), 0);
    if (error) {
        ros.send_failures++;
        ros.failure = error;
        return 0;
    }
    return 1;
}

static void model_ros_deliver(int index) {
    const struct cdr_message *m = &cdr_messages[index];
    int encoded[MAX_SPELLINGS] = {0};
    for (int i = 0; i < ros.nspellings; i++) {
        if (i > 0 && !ros.active[i]) continue;
        int same = -1;
        for (int k = 0; k < i && same < 0; k++)
            if (encoded[k] == 1 && ros.encoder[k] == ros.encoder[i]) same = k;
        if (same >= 0) {
            encoded[i] = 2 + same;
            continue;
        }
        if (rgb_to_pb(&encoder_models[ros.encoder[i]], m->data, m->len, &ros.out[i]) != RGB_OK) {
            ros.refused[ros.nrefused++] = index;
            return;
        }
        encoded[i] = 1;
    }
    int sent_all = 1;
    for (int i = 0; i < ros.nspellings && !ros.failure; i++) {
        if (!ros.active[i]) continue;
        if (!model_send_frames(i, &ros.out[encoded[i] >= 2 ? encoded[i] - 2 : i])) sent_all = 0;
    }
    if (sent_all && !ros.failure) ros.published++;
}

static void check_ros_counts(RosPumpObject *pump) {
    CHECK(pump->received == ros.received && pump->own_skipped == ros.own_skipped);
    CHECK(pump->rate_limited == ros.rate_limited && pump->published == ros.published);
    CHECK(pump->take_errors == ros.take_errors && pump->send_failures == ros.send_failures);
    CHECK(pump->bytes_read == ros.bytes_read && pump->lost == 0);
    CHECK(pump->failure == ros.failure && pump->nrefused == (size_t)ros.nrefused);
    CHECK(ros.expected_sent == nsent && ros.send_calls == send_calls);
    for (int k = 0; k < ros.nrefused; k++) {
        const struct cdr_message *m = &cdr_messages[ros.refused[k]];
        CHECK(pump->refused[k].len == m->len && !memcmp(pump->refused[k].cdr, m->data, m->len));
    }
}

static void ros_turn(PyObject *object, uint8_t arg) {
    RosPumpObject *pump = (RosPumpObject *)object;
    unsigned fired = (arg & 0xc0) == 0xc0 ? RGB_FIRED_ERROR : (arg >> 3) & 1u;
    struct rgb_budget budget = {1 + (arg & 7), INT64_MAX / 4};
    int first = next_take, had_error = take_error;
    int result = rgb_ros_pump_hooks.turn(&pump->member, fired, &budget);
    if (fired & RGB_FIRED_ERROR) ros.failure = EBADF;
    int taken = 0;
    if (!ros.failure && had_error) {
        ros.take_errors++;
        CHECK(next_take == first);
    }
    for (int i = first; i < next_take; i++, taken++) {
        const struct cdr_message *m = &cdr_messages[i];
        ros.received++;
        ros.bytes_read += m->len;
        if (ros.ignored[m->publisher]) {
            ros.own_skipped++;
        } else if (ros.rate_limited_all && ros.admitted) {
            ros.rate_limited++;
        } else {
            ros.admitted = 1;
            model_ros_deliver(i);
        }
    }
    CHECK(taken <= budget.messages);
    check_ros_counts(pump);
    int events = ros.nrefused ? RGB_EVENT_HANDED : 0;
    if (ros.failure) CHECK(result == (events | RGB_EVENT_BROKEN));
    else CHECK(result == (events | (taken == budget.messages ? RGB_AGAIN : 0)));
}

static void ros_take(PyObject *pump) {
    PyObject *refused = call(pump, "take_handed", "()");
    CHECK(PyList_GET_SIZE(refused) == ros.nrefused);
    for (int k = 0; k < ros.nrefused; k++) {
        const struct cdr_message *m = &cdr_messages[ros.refused[k]];
        CHECK(bytes_equal(PyList_GET_ITEM(refused, k), &(struct frame){m->data, m->len}));
    }
    ros.nrefused = 0;
    Py_DECREF(refused);
}

static void set_active(PyObject *pump, uint8_t mask) {
    PyObject *types = PySet_New(NULL);
    for (int i = 0; i < ros.nspellings; i++)
        if (mask >> i & 1) {
            PyObject *type = PyBytes_FromString(ros.type[i]);
            CHECK(type != NULL && PySet_Add(types, type) == 0);
            Py_DECREF(type);
        }
    Py_DECREF(call(pump, "set_active", "(O)", types));
    Py_DECREF(types);
    for (int i = 0; i < ros.nspellings; i++) { /* spellings of one type share its answer */
        ros.active[i] = 0;
        for (int k = 0; k < ros.nspellings; k++)
            if ((mask >> k & 1) && !strcmp(ros.type[k], ros.type[i])) ros.active[i] = 1;
    }
}

static void ignore(PyObject *pump, uint8_t mask) {
    PyObject *publishers = PyList_New(0);
    memset(ros.ignored, 0, sizeof ros.ignored);
    for (int p = 0; p < 8; p++)
        if (mask >> p & 1) {
            PyObject *address = PyLong_FromLong(8 + p); /* never null; its handle and GID: p */
            CHECK(address != NULL && PyList_Append(publishers, address) == 0);
            Py_DECREF(address);
            if (p != 6 && p != 7) ros.ignored[p] = 1;
        }
    PyObject *count = call(pump, "ignore", "(O)", publishers);
    int expected = 0;
    for (int p = 0; p < 8; p++) expected += ros.ignored[p];
    CHECK(PyLong_AsLong(count) == expected);
    Py_DECREF(count);
    Py_DECREF(publishers);
}

/* send(type, payload) from Python (the fallback thread's): a spelling's frames, or False. */
static void python_send(PyObject *pump, const uint8_t **data, size_t *size) {
    if (*size == 0 || python_sends++ == PYTHON_SENDS) return;
    int i = **data % (ros.nspellings + 1); /* nspellings: a type no spelling has */
    (*data)++, (*size)--;
    size_t len = *size < 16 ? *size : 16;
    const char *type = i < ros.nspellings ? ros.type[i] : "gz.msgs.Nobody";
    PyObject *ok = call(pump, "send", "(yy#)", type, (const char *)*data, (Py_ssize_t)len);
    int sent_now = 0;
    if (i < ros.nspellings && !ros.failure) {
        struct rgb_out out = {.data = (uint8_t *)*data, .len = len};
        int first = 0; /* the first spelling of that type */
        while (strcmp(ros.type[first], type)) first++;
        sent_now = model_send_frames(first, &out);
    }
    CHECK(PyObject_IsTrue(ok) == sent_now);
    Py_DECREF(ok);
    *data += len, *size -= len;
}

static PyObject *make_ros_pump(const uint8_t *config) {
    memset(&ros, 0, sizeof ros);
    int e = config[0] % ENCODER_COUNT;
    ros.nspellings = 1 + config[1] % MAX_SPELLINGS;
    ros.rate_limited_all = config[2] & 1;
    PyObject *spellings = PyList_New(0);
    for (int i = 0; i < ros.nspellings; i++) {
        /* bit i of config[1] >> 2: another pair's encoder; bit i of config[2] >> 1: the type of
         * the spelling before (an encoder may serve two spellings, a type two) */
        ros.encoder[i] = config[1] >> (2 + i) & 1 ? (e + 1 + i) % ENCODER_COUNT : e;
        const char *gz = strstr(ENCODERS[ros.encoder[i]].name, "msgs.");
        CHECK(gz != NULL);
        if (i > 0 && (config[2] >> (1 + i) & 1))
            snprintf(ros.type[i], sizeof ros.type[i], "%s", ros.type[i - 1]);
        else
            snprintf(ros.type[i], sizeof ros.type[i], "%s.%s", i % 2 ? "ignition.msgs" : "gz.msgs",
                     gz + strlen("msgs."));
        snprintf(ros.topic[i], sizeof ros.topic[i], "@/loopfuzz@/cmd_vel");
        snprintf(ros.sender[i], sizeof ros.sender[i], "tcp://127.0.0.1:4000%d", i);
        PyObject *item = Py_BuildValue("(yyyO)", ros.type[i], ros.topic[i], ros.sender[i],
                                       encoder_object(ros.encoder[i]));
        CHECK(item != NULL && PyList_Append(spellings, item) == 0);
        Py_DECREF(item);
    }
    static const struct ros_foreign fakes = {
        .take = f_take, .set_callback = f_set_callback, .reset_error = f_reset_error,
        .default_allocator = f_default_allocator, .publisher_rmw_handle = f_publisher_rmw_handle,
        .gid_for_publisher = f_gid_for_publisher, .send = f_send,
    };
    PyObject *addresses = function_addresses(rgb_ros_pump_functions, &fakes);
    PyObject *pump = call(module, "RosPump", "(OKKOd)", addresses, (unsigned long long)1,
                          (unsigned long long)1, spellings, ros.rate_limited_all ? 1e-3 : 0.0);
    Py_DECREF(addresses);
    Py_DECREF(spellings);
    const char *why = NULL;
    CHECK(rgb_ros_pump_hooks.attach(&((RosPumpObject *)pump)->member, &why) == 0);
    CHECK(callback != NULL && callback_data == pump);
    return pump;
}

/* A CDR message of the input: a byte (its publisher, and whether rcl tells of it), then a
 * literal as in a frame (below 0x70: that many bytes; else a 2-byte length). */
static void ros_message(const uint8_t **data, size_t *size) {
    if (*size == 0 || ncdr == MAX_MESSAGES) return;
    uint8_t head = **data;
    (*data)++, (*size)--;
    size_t len = *size ? **data : 0;
    if (*size) (*data)++, (*size)--;
    if (len >= 0x70) {
        len = *size >= 2 ? (size_t)((*data)[0] | (*data)[1] << 8) : 0;
        size_t skip = *size >= 2 ? 2 : *size;
        *data += skip, *size -= skip;
    }
    if (len > *size) len = *size;
    struct cdr_message *m = &cdr_messages[ncdr++];
    m->data = malloc(len ? len : 1);
    CHECK(m->data != NULL);
    memcpy(m->data, *data, len);
    m->len = len;
    m->publisher = head & 7;
    *data += len, *size -= len;
    if (head & 8) callback(callback_data, head >> 4); /* rcl tells the loop (its eventfd) */
}

void fuzz_ros_pump(const uint8_t *data, size_t size) {
    PyObject *pump = make_ros_pump(data);
    data += 4, size -= 4;
    ncdr = next_take = take_error = 0;
    send_calls = nsent = python_sends = 0;
    fail_from = fail_to = 0;
    while (size) {
        uint8_t op = *data++ % OPS;
        size--;
        uint8_t arg = size ? *data : 0;
        switch (op) {
        case OP_MESSAGE:
            ros_message(&data, &size);
            continue;
        case OP_TURN:
            ros_turn(pump, arg);
            break;
        case OP_TAKE:
            ros_take(pump);
            continue;
        case OP_FLOOD: /* the spellings Gazebo subscribers take */
            set_active(pump, arg);
            break;
        case OP_FORGET: /* the bridge's own publishers on the topic */
            ignore(pump, arg);
            break;
        case OP_WATCH: /* the next sends fail: which call, how many, and the errno */
            fail_from = send_calls + (arg & 7);
            fail_to = fail_from + 1 + (arg >> 3 & 3) * 4;
            send_errno = (int[]){EAGAIN, EINTR, ENOTSOCK, EFAULT}[arg >> 5 & 3];
            break;
        case OP_PUBLISH_FAILS:
            python_send(pump, &data, &size);
            continue;
        default:
            take_error = 1;
            continue;
        }
        if (size) data++, size--;
    }
    ros_take(pump);
    check_ros_counts((RosPumpObject *)pump);
    rgb_ros_pump_hooks.detach(&((RosPumpObject *)pump)->member);
    CHECK(callback == NULL);
    Py_DECREF(pump);
    for (int i = 0; i < ncdr; i++) free(cdr_messages[i].data);
    for (int i = 0; i < nsent; i++) free(sent[i].data);
    for (int i = 0; i < MAX_SPELLINGS; i++) rgb_out_free(&ros.out[i]);
}
