/* One native ROS -> Gazebo channel (ros_pump.c) as the shared loop (ros_loop.c) drives it
 * (docs/native.md §7). */
#ifndef RGB_ROS_PUMP_H
#define RGB_ROS_PUMP_H

#include <Python.h>
#include <stdint.h>

#include "encode.h"

/* rcutils_allocator_t, rcl_serialized_message_t, rmw_gid_t and rmw_message_info_t as Jazzy's
 * headers lay them out. */
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
    struct ros_foreign f;
    void *subscription;
    void *sock;
    int event_fd;      /* written by rcl's on-new-message callback */
    int callback_set;
    PyObject *encoders; /* list: keeps the Encoder objects alive; set by the first __init__ */
    int ready;          /* __init__ succeeded */
    struct spelling spellings[MAX_SPELLINGS];
    int nspellings;
    rcl_bytes message;
    struct rgb_out out[MAX_SPELLINGS];
    uint8_t ignored[MAX_IGNORED][GID_SIZE];
    int nignored;
    int64_t period_ns, next_ns;
    unsigned long long received, own_skipped, rate_limited, published, take_errors,
        send_failures;
    unsigned long long lost; /* messages for Python that could not be copied (no memory) */
    uint8_t **refused;
    size_t *refused_len;
    size_t nrefused, refused_cap;
    /* Set when the channel's socket failed (an errno of libzmq): it takes nothing more. */
    int failure;
    /* The shared loop's bookkeeping (ros_loop.c), under its lock. */
    int attached, slot, queued, moved;
} RosPumpObject;

/* Whether `object` is an initialised RosPump. */
int ros_pump_check(PyObject *object);

/* Takes and handles at most `budget` waiting messages; how many were taken. Sets `failure` when
 * the socket failed. */
int ros_pump_drain(RosPumpObject *self, int budget);

/* Sets and clears rcl's on-new-message callback; set returns -1 (no Python error) if rcl
 * refused. */
int ros_pump_set_callback(RosPumpObject *self);
void ros_pump_clear_callback(RosPumpObject *self);

/* Frees the messages left to Python. */
void ros_pump_clear_refused(RosPumpObject *self);

/* Adds the RosLoop type (ros_loop.c) to the module; -1 on error. */
int ros_loop_register(PyObject *module);

#endif
