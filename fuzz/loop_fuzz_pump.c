/* The Gazebo -> ROS half of fuzz/loop_fuzz.c: a Pump (pump.c, pump_loop.c), its fake ZeroMQ
 * socket and rcl publisher, the Python reader that teaches it, and the model checked against it.
 */
#include "loop_fuzz.h"
#include "programs.h"

/* Senders a flood learns in one input: the table (1024 routes) fills and evicts (learning is
 * slow: each route is looked for among the others first). */
#define FLOOD_SENDERS 1100

/* ---- the pump, its Python reader and the model -------------------------------------------- */

static PyObject *programs_of[PROGRAM_COUNT]; /* Program objects, made once */
static struct rgb_program models[PROGRAM_COUNT];
static int loaded[PROGRAM_COUNT];
static struct rgb_out model_out;

static const char *gz_type_of(int p) {
    const char *arrow = strstr(PROGRAMS[p].name, "<- ");
    CHECK(arrow != NULL && strstr(arrow, "msgs.") != NULL);
    return arrow + 3;
}

/* The dictionary's frames (see the header comment). */
static PyObject *gz_payloads[PROGRAM_COUNT];

static struct frame dictionary_frame(int p, unsigned index, const uint8_t **data, size_t *size,
                                     char *scratch) {
    static const char *const fixed[] = {
        "@/loopfuzz@/model/x/pose", "@/loopfuzz@/model/x/pose_static", "@/loopfuzz@/model/x/pose\xff",
        "tcp://127.0.0.1:40001", "tcp://127.0.0.1:40002", "\xff\xfe", "gz.msgs.Unprogrammed",
        "gz.msgs.Other", "",
    };
    size_t nfixed = sizeof fixed / sizeof *fixed;
    index %= nfixed + 5;
    if (index < nfixed) return (struct frame){(uint8_t *)fixed[index], strlen(fixed[index])};
    index -= nfixed;
    if (index < 2) { /* the program's spellings */
        const char *gz = strstr(gz_type_of(p), "msgs.") + strlen("msgs.");
        snprintf(scratch, 256, "%s.msgs.%s", index ? "ignition" : "gz", gz);
        return (struct frame){(uint8_t *)scratch, strlen(scratch)};
    }
    if (index == 2) { /* a valid payload */
        if (gz_payloads[p] == NULL) gz_payloads[p] = call(host_module, "payload", "(s)", gz_type_of(p));
        return (struct frame){(uint8_t *)PyBytes_AS_STRING(gz_payloads[p]),
                              (size_t)PyBytes_GET_SIZE(gz_payloads[p])};
    }
    unsigned arg = 0;
    if (*size) {
        arg = **data;
        (*data)++;
        (*size)--;
    }
    if (index == 3) { /* a flood sender */
        snprintf(scratch, 256, "flood-%u", arg);
        return (struct frame){(uint8_t *)scratch, strlen(scratch)};
    }
    static uint8_t large[256 << 10]; /* a large payload: that many KiB of a repeated field */
    if (large[0] == 0)
        for (size_t i = 0; i + 1 < sizeof large; i += 2) large[i] = 0x08, large[i + 1] = 0x01;
    return (struct frame){large, (size_t)arg << 10};
}

/* What the model expects the pump to have done, since the last take_handed or turn. */
struct expected_handed {
    int kind, message, status;
    size_t items, least;
};

/* In a shared input (the configuration's 0x20), the pump is a peer of this reader, which the
 * turns turn: it reads the socket and puts the pump's messages in its queue. */
static PyObject *reader;

static struct model {
    int p, capacity, rate_limited_all, guarded;
    unsigned long long read, foreign; /* by the reader: all messages, those of no peer */
    size_t max_bytes, watch_above;
    int ring[MAX_MESSAGES], head, count; /* message indices */
    size_t queued_bytes;
    struct expected_handed handed[MAX_MESSAGES];
    int nhanded;
    size_t grown;
    unsigned long long received, rate_limited, published, dropped, skipped, taken, bytes_read;
    int admitted;     /* max_rate: the first message only */
    int last_dropped; /* the message dropped last */
    int next_published;
} model;

static void check_counts(PumpObject *pump) {
    CHECK(pump->received == model.received && pump->rate_limited == model.rate_limited);
    CHECK(pump->published == model.published && pump->dropped == model.dropped);
    CHECK(pump->skipped == model.skipped && pump->taken == model.taken);
    CHECK(pump->bytes_read == model.bytes_read && pump->lost == 0);
    CHECK(pump->count == (size_t)model.count && pump->queued_bytes == model.queued_bytes);
    CHECK(pump->nhanded == (size_t)model.nhanded && pump->grown == model.grown);
    CHECK(live == model.count); /* only the queued payloads are open */
    if (reader == NULL) return;
    PumpObject *r = (PumpObject *)reader;
    CHECK(r->taken == model.read && r->skipped == model.foreign && r->nhanded == 0);
    CHECK(r->count == 0 && r->bytes_read == model.bytes_read && r->published == 0);
}

static size_t payload_size(int index) { return messages[index].frames[2].size; }

/* The model's fate of message `index`, read with the routes the pump holds now. */
static void model_read(PumpObject *pump, int index) {
    struct message *m = &messages[index];
    int n = m->n < PUMP_FRAMES ? m->n : PUMP_FRAMES;
    model.read++;
    if (reader != NULL && !(m->frames[0].size == pump->topic_len &&
                            !memcmp(m->frames[0].data, pump->topic, pump->topic_len))) {
        model.foreign++; /* the reader's, skipped: a topic the pump's prefixes */
        return;
    }
    model.taken++;
    if (n > 2) {
        model.bytes_read += m->frames[2].size;
        if (m->frames[2].size > model.watch_above && m->frames[2].size > model.grown)
            model.grown = m->frames[2].size;
    }
    int route = -1;
    if (m->n == 4 && m->frames[0].size == pump->topic_len &&
        !memcmp(m->frames[0].data, pump->topic, pump->topic_len))
        route = pump_find_route(pump, m->frames[1].data, m->frames[1].size, m->frames[3].data,
                                m->frames[3].size);
    if (route < 0) {
        model.handed[model.nhanded++] = (struct expected_handed){HANDED_UNROUTED, index, 0, 0, 0};
        return;
    }
    /* The reference: Python delivers what the pump takes, and nothing the pump skips. */
    int takes = python_takes(m);
    if (pump->routes[route].program < 0) {
        if (takes) {
            fprintf(stderr, "loop_fuzz: the pump skips a message the Python reader delivers\n");
            abort();
        }
        model.skipped++;
        return;
    }
    if (!takes) {
        fprintf(stderr, "loop_fuzz: the pump takes a message the Python reader does not\n");
        abort();
    }
    size_t size = payload_size(index);
    while (model.count && (model.count == model.capacity ||
                           model.queued_bytes + size > model.max_bytes)) {
        int oldest = model.ring[model.head];
        model.queued_bytes -= payload_size(oldest);
        model.head = (model.head + 1) % model.capacity;
        model.count--;
        model.dropped++;
        model.last_dropped = oldest;
    }
    model.ring[(model.head + model.count) % model.capacity] = index;
    model.count++;
    model.queued_bytes += size;
}

static void model_deliver(int index) {
    model.received++;
    if (model.rate_limited_all) {
        if (model.admitted) {
            model.rate_limited++;
            return;
        }
        model.admitted = 1;
    }
    const struct frame *payload = &messages[index].frames[2];
    enum rgb_status status = rgb_to_cdr(&models[model.p], payload->data, payload->size,
                                        &model_out, NULL);
    if (status == RGB_OK && !publish_fails) {
        CHECK(model.next_published < npublished);
        const struct frame *out = &published[model.next_published++];
        CHECK(out->size == model_out.len && !memcmp(out->data, model_out.data, out->size));
        model.published++;
        return;
    }
    if (status == RGB_OK) status = RGB_FALLBACK;
    struct expected_handed h = {status == RGB_TOO_LARGE ? HANDED_TOO_LARGE : HANDED_REFUSED,
                                index, (int)status, 0, 0};
    if (status == RGB_TOO_LARGE) {
        h.items = model_out.refused.items;
        h.least = model_out.refused.least;
    }
    model.handed[model.nhanded++] = h;
}

/* The loop guard's question on the last publication: the sample rcl delivers back is the
 * pump's own (is_own: its sequence, a time in its window, its bytes); with other bytes (one
 * more, not a zero: another body) it is not, where the pump keeps digests (guard); a sample
 * cut short (its header, or less) is asked too, and is the pump's only where its digest is. */
static int is_own(PyObject *pump, const uint8_t *data, size_t len) {
    PumpObject *p = (PumpObject *)pump;
    const struct window *w = &p->windows[p->sequence % PUMP_HISTORY];
    CHECK(w->sequence == p->sequence && w->end >= w->start);
    PyObject *own = call(pump, "is_own", "(KLy#)", (unsigned long long)p->sequence,
                         (long long)w->start, (const char *)data, (Py_ssize_t)len);
    int result = own == Py_True;
    Py_DECREF(own);
    return result;
}

static void check_own(PyObject *pump) {
    const struct frame *last = &published[npublished - 1];
    CHECK(is_own(pump, last->data, last->size));
    uint8_t *other = malloc(last->size + 1);
    CHECK(other != NULL);
    memcpy(other, last->data, last->size);
    other[last->size] = 1;
    CHECK(is_own(pump, other, last->size + 1) == !model.guarded);
    free(other);
    size_t cut = last->size < 4 ? last->size : 4;
    for (size_t n = 0; n <= cut; n++)
        CHECK(is_own(pump, last->data, n) ==
              (!model.guarded || rgb_cdr_digest(last->data, n) ==
                                     rgb_cdr_digest(last->data, last->size)));
}

/* One turn of the pump, as the loop makes it, and the model's account of it. */
static void turn(PyObject *object, uint8_t arg) {
    PumpObject *pump = (PumpObject *)object;
    PumpObject *turned = reader != NULL ? (PumpObject *)reader : pump;
    check_routes(pump);
    unsigned fired = (arg >> 3) & (turned->monitor != NULL ? 3u : 1u);
    if ((arg & 0xc0) == 0xc0) fired = RGB_FIRED_ERROR;
    struct rgb_budget budget = {1 + (arg & 7), INT64_MAX / 4}; /* the slice never ends a turn */
    monitor_events = arg & 0x20 ? 1 : 0;
    int first = next_read, handed_before = model.nhanded, was_breaking = breaking;
    int published_before = npublished;
    unsigned long long dropped_before = model.dropped;
    int result = rgb_pump_hooks.turn(&turned->member, fired, &budget);
    for (int i = first; i < next_read; i++) model_read(pump, i);
    CHECK(next_read - first <= budget.messages);
    int deliveries = model.count < budget.messages ? model.count : budget.messages;
    if (fired & RGB_FIRED_ERROR) deliveries = 0;
    for (int i = 0; i < deliveries; i++) {
        int index = model.ring[model.head];
        model.head = (model.head + 1) % model.capacity;
        model.count--;
        model.queued_bytes -= payload_size(index);
        model_deliver(index);
    }
    CHECK(model.next_published == npublished);
    if (npublished > published_before) check_own(object);
    check_counts(pump);
    if (model.dropped != dropped_before) { /* the sender of the last one dropped, cut */
        const struct frame *sender = &messages[model.last_dropped].frames[1];
        size_t cut = sender->size < PUMP_SENDER_MAX ? sender->size : PUMP_SENDER_MAX;
        CHECK(pump->drop_sender_len == cut && !memcmp(pump->drop_sender, sender->data, cut));
    }
    /* The hand-over, entry by entry. */
    for (int k = handed_before; k < model.nhanded; k++) {
        const struct handed *h = &pump->handover[k];
        const struct expected_handed *e = &model.handed[k];
        const struct message *m = &messages[e->message];
        CHECK(h->kind == e->kind);
        if (e->kind == HANDED_UNROUTED) {
            int n = m->n < PUMP_FRAMES ? m->n : PUMP_FRAMES;
            CHECK(h->nframes == n);
            for (int f = 0; f < n; f++)
                CHECK(h->size[f] == m->frames[f].size &&
                      !memcmp(h->data[f], m->frames[f].data, h->size[f]));
        } else if (e->kind == HANDED_REFUSED) {
            CHECK(h->status == e->status && h->nframes == 1);
            CHECK(h->size[0] == m->frames[2].size && !memcmp(h->data[0], m->frames[2].data, h->size[0]));
        } else {
            CHECK(h->items == e->items && h->least == e->least && h->payload_size == m->frames[2].size);
        }
    }
    if (fired & RGB_FIRED_ERROR) {
        CHECK(result == RGB_EVENT_BROKEN && next_read == first);
        return;
    }
    CHECK(!!(result & RGB_EVENT_MONITOR) == ((fired & 2) && monitor_events));
    CHECK(!!(result & RGB_EVENT_HANDED) == (model.nhanded > 0 || model.grown > 0));
    if (was_breaking && !breaking && next_read == first) CHECK(result & RGB_EVENT_BROKEN);
    CHECK(!(result & RGB_AGAIN) == (!turned->readable && !model.count));
}

/* take_handed, checked against the model; then the unrouted frames judged by the reader. */
static void take(PyObject *pump) {
    PyObject *handover = call(pump, "take_handed", "()");
    PyObject *lists[3];
    for (int k = 0; k < 3; k++) lists[k] = PyStructSequence_GetItem(handover, k);
    Py_ssize_t at[3] = {0, 0, 0};
    for (int i = 0; i < model.nhanded; i++) {
        const struct expected_handed *e = &model.handed[i];
        const struct message *m = &messages[e->message];
        CHECK(at[e->kind] < PyList_GET_SIZE(lists[e->kind]));
        PyObject *item = PyList_GET_ITEM(lists[e->kind], at[e->kind]++);
        if (e->kind == HANDED_UNROUTED) {
            int n = m->n < PUMP_FRAMES ? m->n : PUMP_FRAMES;
            CHECK(PyList_Check(item) && PyList_GET_SIZE(item) == n);
            for (int f = 0; f < n; f++) CHECK(bytes_equal(PyList_GET_ITEM(item, f), &m->frames[f]));
            continue;
        }
        /* a refusal names the message's route: its sender and type, whatever the evictions */
        CHECK(bytes_equal(PyStructSequence_GetItem(item, 0), &m->frames[1]));
        CHECK(bytes_equal(PyStructSequence_GetItem(item, 1), &m->frames[3]));
        if (e->kind == HANDED_REFUSED) {
            CHECK(bytes_equal(PyStructSequence_GetItem(item, 2), &m->frames[2]));
            CHECK(PyLong_AsLong(PyStructSequence_GetItem(item, 3)) == e->status);
        } else {
            CHECK(PyLong_AsSize_t(PyStructSequence_GetItem(item, 4)) == m->frames[2].size);
        }
    }
    for (int k = 0; k < 3; k++) CHECK(at[k] == PyList_GET_SIZE(lists[k]));
    CHECK(PyLong_AsSize_t(PyStructSequence_GetItem(handover, 3)) == model.grown);
    model.nhanded = 0;
    model.grown = 0;
    Py_ssize_t n = PyList_GET_SIZE(lists[0]);
    for (Py_ssize_t i = 0; i < n; i++) Py_DECREF(call(host, "judge", "(O)", PyList_GET_ITEM(lists[0], i)));
    Py_DECREF(handover);
    check_routes((PumpObject *)pump);
}

/* `count` distinct senders of the program's type learned, as the reader learns them (it takes
 * every sender of the topic's spellings): the table fills, and evicts. */
static void flood(PyObject *pump, unsigned count, unsigned *serial) {
    char sender[64];
    for (unsigned i = 0; i < count && *serial < FLOOD_SENDERS; i++) {
        snprintf(sender, sizeof sender, "flood-%u", (*serial)++);
        Py_DECREF(call(pump, "learn", "(yyi)", sender, gz_type_of(model.p), 1));
    }
    check_routes((PumpObject *)pump);
}

static PyObject *make_pump(const uint8_t *config) {
    int p = config[0] % PROGRAM_COUNT;
    if (!loaded[p]) {
        const char *why = NULL;
        CHECK(rgb_load(&models[p], PROGRAMS[p].schema, PROGRAMS[p].schema_len, PROGRAMS[p].ops,
                       PROGRAMS[p].ops_len, &why) == 0);
        PyObject *program = call(module, "Program", "(y#y#)", (char *)PROGRAMS[p].schema,
                                 (Py_ssize_t)(PROGRAMS[p].schema_len * 4), (char *)PROGRAMS[p].ops,
                                 (Py_ssize_t)(PROGRAMS[p].ops_len * 4));
        programs_of[p] = program;
        loaded[p] = 1;
    }
    memset(&model, 0, sizeof model);
    model.p = p;
    model.capacity = 1 + config[1] % 8;
    model.max_bytes = (size_t)1 << (config[2] % 21);
    model.rate_limited_all = config[3] & 1;
    static const long long watched[] = {-1, 0, 64, 4096};
    long long watch = watched[(config[3] >> 2) & 3];
    model.watch_above = watch < 0 ? SIZE_MAX : (size_t)watch;
    PyObject *spellings = call(host_module, "spellings", "(s)", gz_type_of(p));
    PyObject *programs = PyDict_New();
    for (Py_ssize_t i = 0; i < PyList_GET_SIZE(spellings); i++)
        CHECK(PyDict_SetItem(programs, PyList_GET_ITEM(spellings, i), programs_of[p]) == 0);
    PyObject *addresses = fake_zmq_functions();
    PyObject *pump = call(module, "Pump", "(yOKOndn)", "@/loopfuzz@/model/x/pose", addresses,
                          (unsigned long long)1, programs, (Py_ssize_t)model.capacity,
                          model.rate_limited_all ? 1e-3 : 0.0, (Py_ssize_t)model.max_bytes);
    reader = NULL;
    if (config[3] & 0x20) { /* no publisher, no program: it reads for the pump */
        reader = call(module, "Pump", "(yOKNndn)", "", addresses, (unsigned long long)0,
                      PyDict_New(), (Py_ssize_t)1, 0.0, (Py_ssize_t)1);
        Py_DECREF(call(reader, "share", "([O])", pump));
    }
    Py_DECREF(call(reader != NULL ? reader : pump, "read_from", "(KK)", (unsigned long long)1,
                   (unsigned long long)(config[3] & 2 ? 2 : 0)));
    Py_DECREF(call(pump, "watch", "(L)", watch));
    model.guarded = config[3] >> 4 & 1;
    if (model.guarded) Py_DECREF(call(pump, "guard", "()"));
    Py_DECREF(call(host, "reset", "(OO)", pump, spellings));
    Py_DECREF(addresses);
    Py_DECREF(programs);
    Py_DECREF(spellings);
    return pump;
}

static int starts_with_topic(const struct message *m) {
    static const char topic[] = "@/loopfuzz@/model/x/pose";
    return m->frames[0].size >= sizeof topic - 1 && !memcmp(m->frames[0].data, topic, sizeof topic - 1);
}

/* A message of the input; kept (copied) when the SUB socket would receive it. */
static void read_message_op(const uint8_t **data, size_t *size) {
    if (*size == 0 || nmessages == MAX_MESSAGES) return;
    struct message *m = &messages[nmessages];
    memset(m, 0, sizeof *m);
    int n = 1 + **data % MAX_FRAMES;
    (*data)++, (*size)--;
    char scratch[256];
    for (int k = 0; k < n && *size; k++) {
        uint8_t spec = **data;
        (*data)++, (*size)--;
        struct frame f;
        if (spec >= 0x80) {
            f = dictionary_frame(model.p, spec & 0x7f, data, size, scratch);
        } else {
            size_t len = spec;
            if (spec >= 0x70) {
                len = *size >= 2 ? (size_t)((*data)[0] | (*data)[1] << 8) : 0;
                size_t skip = *size >= 2 ? 2 : *size;
                *data += skip, *size -= skip;
            }
            if (len > *size) len = *size;
            f = (struct frame){(uint8_t *)*data, len};
            *data += len, *size -= len;
        }
        m->frames[k].data = malloc(f.size ? f.size : 1);
        CHECK(m->frames[k].data != NULL);
        memcpy(m->frames[k].data, f.data, f.size);
        m->frames[k].size = f.size;
        m->n = k + 1;
    }
    if (m->n == 0 || !starts_with_topic(m)) { /* ZeroMQ's subscription filter drops it */
        for (int k = 0; k < m->n; k++) free(m->frames[k].data);
        return;
    }
    nmessages++;
}

void fuzz_pump(const uint8_t *data, size_t size) {
    PyObject *pump = make_pump(data);
    data += 4, size -= 4;
    nmessages = next_read = next_frame = 0;
    breaking = publish_fails = 0;
    npublished = 0;
    unsigned serial = 0;
    while (size) {
        uint8_t op = *data++ % OPS;
        size--;
        uint8_t arg = size ? *data : 0;
        switch (op) {
        case OP_MESSAGE:
            read_message_op(&data, &size);
            continue;
        case OP_TURN:
            turn(pump, arg);
            break;
        case OP_TAKE:
            take(pump);
            continue;
        case OP_FLOOD:
            flood(pump, arg < 0xf0 ? 1u + arg % 64u : FLOOD_SENDERS, &serial);
            break;
        case OP_FORGET:
            take(pump);
            if (reader != NULL) Py_DECREF(call(reader, "share", "([])")); /* a peer forgets nothing */
            Py_DECREF(call(pump, "forget", "()")); /* closes the queue's payloads */
            if (reader != NULL) Py_DECREF(call(reader, "share", "([O])", pump));
            model.dropped += model.count; /* counted dropped */
            model.count = model.head = 0;
            model.queued_bytes = 0;
            check_counts((PumpObject *)pump);
            continue;
        case OP_WATCH: {
            long long watch = arg == 0xff ? -1 : (long long)arg << (arg & 3) * 4;
            Py_DECREF(call(pump, "watch", "(L)", watch));
            model.watch_above = watch < 0 ? SIZE_MAX : (size_t)watch;
            break;
        }
        case OP_PUBLISH_FAILS:
            publish_fails = !publish_fails;
            continue;
        default:
            breaking = 1;
            continue;
        }
        if (size) data++, size--;
    }
    take(pump);
    check_counts((PumpObject *)pump);
    Py_XDECREF(reader); /* the pump's last reference is the test's */
    reader = NULL;
    Py_DECREF(pump); /* the queue's payloads are closed with it */
    CHECK(live == 0);
    for (int i = 0; i < nmessages; i++)
        for (int k = 0; k < messages[i].n; k++) free(messages[i].frames[k].data);
    for (int i = 0; i < npublished; i++) free(published[i].data);
}
