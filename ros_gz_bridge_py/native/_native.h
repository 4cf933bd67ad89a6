/* What the C files of the extension share (private; docs/native.md).
 *
 * One type a file, as CPython's Modules/_io: transcoders.c (Program, Encoder: the two
 * transcoders' Python faces), pump.c (Pump: one Gazebo -> ROS channel) and ros_pump.c (RosPump:
 * one ROS -> Gazebo channel), each with its per-message work beside it (pump_loop.c,
 * ros_pump_loop.c), loop.c (Loop: the one loop that runs either kind of pump, once per
 * direction) and _native.c (the module: its constants, the named structures the types return,
 * the helpers below). The transcoders' own headers (transcode.h, encode.h, wire.h) stay apart:
 * the fuzz targets build them without Python. */
#ifndef RGB_NATIVE_H
#define RGB_NATIVE_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <time.h>

#include "encode.h"
#include "transcode.h"
#include "wire.h"

/* ---- the module (_native.c) --------------------------------------------------------------- */

extern PyTypeObject rgb_ProgramType, rgb_EncoderType, rgb_PumpType, rgb_RosPumpType, rgb_LoopType;

/* The named structures the types return (struct sequences, made at import). */
extern struct rgb_records {
    PyTypeObject *pump_counts, *ros_pump_counts, *handover, *refused, *too_large;
} rgb_records;

/* A record of `type` holding the items of `values` (a tuple, stolen; NULL passes through). */
PyObject *rgb_record(PyTypeObject *type, PyObject *values);
/* A function of a foreign library a type calls: its name, and where its pointer goes in the
 * type's table of them (struct zmq_foreign, struct ros_foreign). Each type's list, ended by a
 * NULL name, is the one declaration of what it calls: exported to Python (PUMP_FUNCTIONS,
 * ROS_PUMP_FUNCTIONS), which finds each function's address by that name (abi.py). */
struct rgb_function {
    const char *name;
    size_t offset;
};
extern const struct rgb_function rgb_pump_functions[], rgb_ros_pump_functions[];
/* Fills the table at `table` from `addresses` (a dict of name to address) by the names of
 * `functions`; -1 with a Python error where one is missing or null. */
int rgb_functions(PyObject *addresses, const struct rgb_function *functions, void *table);
/* A copy of `n` bytes (malloc; NULL only when memory runs out). */
uint8_t *rgb_copy(const void *p, size_t n);
int64_t rgb_now_ns(clockid_t clock);
/* `n` as a Py_ssize_t, PY_SSIZE_T_MAX where it is larger. */
static inline Py_ssize_t rgb_clamp(size_t n) {
    return n > (size_t)PY_SSIZE_T_MAX ? PY_SSIZE_T_MAX : (Py_ssize_t)n;
}
/* The loaded program or encoder `object` is, or NULL when it is not one (transcoders.c). */
struct rgb_program *rgb_program_of(PyObject *object);
struct rgb_encoder *rgb_encoder_of(PyObject *object);

/* ---- the loop and its members (loop.c) ------------------------------------------------------ */

/* What one member gets per turn before the others have theirs: messages (read, delivered or
 * taken) and time. Python's one definition fills it (transport/budget.py, docs/native.md §5). */
struct rgb_budget {
    int messages;
    int64_t slice_ns;
};

/* What a member's turn tells Python (exported as EVENT_*), and that it has more to do at once
 * (RGB_AGAIN: it stays active, and the loop does not sleep). */
enum { RGB_EVENT_HANDED = 1, RGB_EVENT_MONITOR = 2, RGB_EVENT_BROKEN = 4, RGB_AGAIN = 8 };
/* A member sleeps on at most this many descriptors; bit i of `fired` is its i-th, this one
 * an error on any of them (EPOLLERR, EPOLLHUP). */
#define RGB_MAX_FDS 2
#define RGB_FIRED_ERROR 0x80u

struct rgb_member;
/* The one difference between the directions: each kind of member's hooks (pump_loop.c,
 * ros_pump_loop.c), all under the loop's mutex: `turn` on the loop's thread without the GIL, the
 * others on the thread that adds or removes the member. */
struct rgb_hooks {
    /* The descriptors to sleep on, fds[0..n); n, or -1 with a reason in *why. */
    int (*descriptors)(struct rgb_member *m, int fds[RGB_MAX_FDS], const char **why);
    /* Joining (0, or -1 with a reason) and leaving the loop. */
    int (*attach)(struct rgb_member *m, const char **why);
    void (*detach)(struct rgb_member *m);
    /* One turn, on the loop's thread: `fired` says which descriptors fired since the last
     * (all of them when Python turned the member); RGB_EVENT_* | RGB_AGAIN. */
    int (*turn)(struct rgb_member *m, unsigned fired, const struct rgb_budget *budget);
    /* Messages taken so far: what moves when the member moves (Loop.moved). */
    unsigned long long (*progress)(const struct rgb_member *m);
};

/* The head of every member object, after PyObject_HEAD (MemberObject). */
struct rgb_member {
    const struct rgb_hooks *hooks; /* set last by __init__: NULL until the member is whole */
    const atomic_int *running; /* while in a loop: its flag, set while it runs without Python */
    pthread_mutex_t *lock;     /* while in a loop: its mutex, held by its passes */
    int slot;                  /* while in a loop: where it holds the member */
};

typedef struct {
    PyObject_HEAD
    struct rgb_member member;
} MemberObject;

/* The object of type `type` whose head is `m`. */
#define RGB_OWNER(type, m) ((type *)((char *)(m) - offsetof(type, member)))

/* The member `object` is (an initialised Pump or RosPump), or NULL. */
struct rgb_member *rgb_member_of(PyObject *object);
/* 0, or -1 with a RuntimeError (`unset`) where the member, a `what`, was never initialised
 * (__new__ alone: no functions to call), or (`idle`) while the loop that holds it runs it:
 * Python may not change a member then. */
int rgb_member_usable(const struct rgb_member *m, int idle, const char *what, const char *unset);

/* ---- a Gazebo -> ROS channel (pump.c, pump_loop.c) ------------------------------------------ */

/* zmq_msg_t: 64 bytes, aligned as a pointer (zmq.h; abi.py checks the loaded libzmq). */
typedef union {
    unsigned char bytes[64];
    void *align;
} zmq_msg;

struct zmq_foreign {
    int (*msg_init)(zmq_msg *msg);
    int (*msg_recv)(zmq_msg *msg, void *socket, int flags);
    int (*msg_close)(zmq_msg *msg);
    void *(*msg_data)(zmq_msg *msg);
    size_t (*msg_size)(const zmq_msg *msg);
    int (*msg_more)(const zmq_msg *msg);
    int (*getsockopt)(void *socket, int option, void *value, size_t *length);
    int (*publish)(const void *publisher, const void *message, void *allocation);
    void (*reset_error)(void);
};

#define PUMP_FRAMES 16
#define PUMP_HISTORY 1024
/* Bytes of a dropped payload's sender kept for the warning that names it (longer: cut). */
#define PUMP_SENDER_MAX 256

/* What a (sender, type) pair of frames gets: a program, or nothing (another spelling taken). */
struct route {
    uint8_t *sender, *type;
    size_t sender_len, type_len;
    int program;   /* index into programs, or -1: skip without a word */
    uint64_t used; /* the pump's `taken` when a message last took this route */
};

struct queued {
    zmq_msg payload;
    int route;
};

/* A message handed to Python: its frames (no route), its payload (refused by its program), or
 * why it is too large (RGB_TOO_LARGE: no copy, Python only words the refusal). */
enum { HANDED_UNROUTED, HANDED_REFUSED, HANDED_TOO_LARGE };
struct handed {
    int kind;
    int route, status, nframes;
    uint8_t *data[PUMP_FRAMES];
    size_t size[PUMP_FRAMES];
    size_t items, least, payload_size; /* HANDED_TOO_LARGE */
};

struct window {
    uint64_t sequence;
    int64_t start, end;
    uint64_t digest; /* rgb_cdr_digest of what was published; 0: not known */
};

typedef struct PumpObject {
    PyObject_HEAD
    struct rgb_member member;
    struct zmq_foreign f;
    void *publisher; /* NULL: a pump that only reads for its peers (no programs) */
    void *sock, *monitor; /* what the loop reads (read_from), the monitor may be NULL */
    int readable;         /* not known to be empty: read it again before sleeping */
    uint8_t *topic;
    size_t topic_len;
    PyObject *program_objects; /* list, keeps the programs alive */
    struct pump_program {
        struct rgb_program *program;
        uint8_t *type; /* the wire type it takes */
        size_t type_len;
    } *programs;
    int nprograms;
    struct route *routes;
    int nroutes;
    struct queued *ring;
    size_t capacity, head, count;
    size_t max_bytes, queued_bytes; /* the ring's bound in payload bytes, and what it holds */
    /* A payload larger than watch_above (SIZE_MAX: none) is told to Python (Handover.grown):
     * the socket's owner lowers its receive HWM for it (transport/zmq/socket_owner.py). */
    size_t watch_above, grown;
    struct handed *handover;
    size_t nhanded, handed_cap;
    size_t handed_bytes; /* the bytes of the copies handed (a read ends past max_bytes) */
    struct rgb_out out;
    int64_t period_ns, next_ns; /* max_rate: next admission time (period 0: no limit) */
    unsigned long long received, rate_limited, published, dropped, skipped;
    unsigned long long lost;       /* messages for Python that could not be copied (no memory) */
    unsigned long long taken;      /* messages read from the socket, whatever became of them */
    unsigned long long bytes_read; /* their payload bytes (the loop's trim after a burst) */
    uint8_t drop_sender[PUMP_SENDER_MAX]; /* the sender of the last payload dropped */
    size_t drop_sender_len;
    pthread_mutex_t lock; /* the windows and the sequence (read by is_own from any thread) */
    uint64_t sequence;
    int guarded; /* (atomic) a subscription of the bridge reads the topic: keep digests */
    struct window windows[PUMP_HISTORY];
    /* One socket for several topics (`share`): this pump reads the messages of its peers'
     * topics into their queues and delivers them in its own turns. The peers, by topic hash
     * (open addressing, `peer_slots` a power of two at least twice their number; NULL: free),
     * kept alive by `peer_objects`; those with messages queued or handed, in `due`. A peer names
     * the pump that reads for it (`reader`, borrowed) and reads nothing itself. */
    PyObject *peer_objects;
    struct PumpObject **peers, **due, *reader;
    size_t peer_slots, npeers, ndue;
    int is_due;
} PumpObject;

extern const struct rgb_hooks rgb_pump_hooks;
int pump_find_route(PumpObject *self, const uint8_t *sender, size_t sender_len,
                    const uint8_t *type, size_t type_len);
/* Publication windows (the loop guard, core/loop_guard.py); a digest of 0 is not known. */
uint64_t rgb_cdr_digest(const uint8_t *cdr, size_t len);
uint64_t pump_begin_publication(PumpObject *self, uint64_t digest);
void pump_end_publication(PumpObject *self, uint64_t sequence, int ok, uint64_t digest);
void pump_clear_ring(PumpObject *self);
/* 0, or -1 with a RuntimeError where the pump (or, for a peer, its reader) was never
 * initialised or (`idle`) its loop runs it; out of a loop and read for by no other. */
int pump_usable(PumpObject *self, int idle);
int pump_out_of_loop(PumpObject *self, const char *what);
/* Reading for peers (pump_share.c): share(peers), and letting them go; where a topic's peer
 * is looked for first. */
PyObject *pump_share(PumpObject *self, PyObject *peers);
void pump_release_peers(PumpObject *self);
size_t pump_topic_hash(const uint8_t *topic, size_t len);
void pump_clear_handover(PumpObject *self);

/* ---- a ROS -> Gazebo channel (ros_pump.c, ros_pump_loop.c) --------------------------------- */

/* rcutils_allocator_t, rcl_serialized_message_t, rmw_gid_t and rmw_message_info_t as Jazzy's
 * headers lay them out (abi.py checks the loaded rclpy). */
typedef struct {
    void *(*allocate)(size_t size, void *state);
    void (*deallocate)(void *pointer, void *state);
    void *(*reallocate)(void *pointer, size_t size, void *state);
    void *(*zero_allocate)(size_t count, size_t size, void *state);
    void *state;
} rcu_allocator;

typedef struct {
    uint8_t *buffer;
    size_t buffer_length;
    size_t buffer_capacity;
    rcu_allocator allocator;
} rcl_bytes;

#define GID_SIZE 16
typedef struct {
    const char *implementation_identifier;
    uint8_t data[GID_SIZE];
} rmw_gid;

typedef struct {
    int64_t source_timestamp;
    int64_t received_timestamp;
    uint64_t publication_sequence_number;
    uint64_t reception_sequence_number;
    rmw_gid publisher_gid;
    _Bool from_intra_process;
} rmw_info;

typedef void (*event_callback)(const void *user_data, size_t number_of_events);

struct ros_foreign {
    int (*take)(const void *subscription, rcl_bytes *message, rmw_info *info, void *allocation);
    int (*set_callback)(const void *subscription, event_callback callback, const void *user_data);
    void (*reset_error)(void);
    rcu_allocator (*default_allocator)(void);
    void *(*publisher_rmw_handle)(const void *publisher);
    int (*gid_for_publisher)(const void *rmw_publisher, rmw_gid *gid);
    int (*send)(void *socket, const void *buffer, size_t length, int flags);
};

#define MAX_SPELLINGS 4
#define MAX_IGNORED 16

struct spelling {
    uint8_t *type, *topic, *sender;
    size_t type_len, topic_len, sender_len;
    struct rgb_encoder *encoder;
    int active;
};

typedef struct {
    PyObject_HEAD
    struct rgb_member member;
    struct ros_foreign f;
    void *subscription;
    void *sock;
    int event_fd; /* written by rcl's on-new-message callback */
    int callback_set;
    PyObject *encoders; /* list: keeps the Encoder objects alive; set by the first __init__ */
    struct spelling spellings[MAX_SPELLINGS];
    int nspellings;
    rcl_bytes message;
    struct rgb_out out[MAX_SPELLINGS];
    uint8_t ignored[MAX_IGNORED][GID_SIZE];
    int nignored;
    int64_t period_ns, next_ns;
    unsigned long long received, own_skipped, rate_limited, published, take_errors,
        send_failures, bytes_read;
    unsigned long long lost; /* messages for Python that could not be copied (no memory) */
    struct refused {
        uint8_t *cdr;
        size_t len;
    } *refused; /* the messages for Python, copied */
    size_t nrefused, refused_cap;
    /* Set when the channel's socket or eventfd failed (an errno): it takes nothing more. */
    int failure;
} RosPumpObject;

extern const struct rgb_hooks rgb_ros_pump_hooks;
/* The four data frames of one message in spelling `s`; 1 when sent (ros_pump_loop.c). */
int ros_pump_send_frames(RosPumpObject *self, const struct spelling *s, const struct rgb_out *out);
void ros_pump_clear_callback(RosPumpObject *self);
void ros_pump_clear_refused(RosPumpObject *self);

/* max_rate's admission (core/rate_limit.py): 1 when a message may go now; *next_ns is the
 * next time on the schedule (INT64_MIN before the first), period_ns 0: no limit. */
int rgb_admit(int64_t *next_ns, int64_t period_ns);

#endif
