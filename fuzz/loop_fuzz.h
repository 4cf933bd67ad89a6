/* What the parts of fuzz/loop_fuzz.c share: its Python, its checks, its operations (its
 * comment says what the target does). */
#ifndef LOOP_FUZZ_H
#define LOOP_FUZZ_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "_native.h"

#define MAX_MESSAGES 512

#define CHECK(cond)                                                                        \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            fprintf(stderr, "loop_fuzz: check failed at line %d: %s\n", __LINE__, #cond); \
            abort();                                                                       \
        }                                                                                  \
    } while (0)

struct frame {
    uint8_t *data;
    size_t size;
};

/* ---- the Pump's fake ZeroMQ socket and rcl publisher (loop_fuzz_zmq.c) ------------------ */

#define MAX_FRAMES 18

struct message {
    struct frame frames[MAX_FRAMES];
    int n;
};

/* The input's messages, those read so far and the frame being read; set: the next read fails
 * (the socket closed), the monitor has an event, rcl refuses to publish. */
extern struct message messages[MAX_MESSAGES];
extern int nmessages, next_read, next_frame;
extern int breaking, monitor_events, publish_fails;
extern long live; /* ZeroMQ messages received and not closed */
/* What rcl was given to publish: copies, in order. */
extern struct frame published[MAX_MESSAGES];
extern int npublished;
/* The fake functions a Pump is made with (pump.c pump_init): {name: address}. */
PyObject *fake_zmq_functions(void);

/* The operations, by opcode (modulo OPS); a RosPump reads the same opcodes otherwise. */
enum { OP_MESSAGE, OP_TURN, OP_TAKE, OP_FLOOD, OP_FORGET, OP_WATCH, OP_PUBLISH_FAILS, OP_BREAK,
       OPS };

/* The extension's module, the Python reader (tests/unit/native/loop_fuzz_host.py) and its
 * module (loop_fuzz.c). */
extern PyObject *module, *host, *host_module;
/* object.name(*args), args built from `format`; a failure prints Python's error and aborts. */
PyObject *call(PyObject *object, const char *name, const char *format, ...);
int bytes_equal(PyObject *object, const struct frame *f);
/* {name: address} of each of `functions` (rgb_pump_functions, rgb_ros_pump_functions), the
 * address read from its place in `table` (a struct zmq_foreign or ros_foreign of fakes). */
PyObject *function_addresses(const struct rgb_function *functions, const void *table);

/* The routes `pump` holds, checked whole; whether the Python reader delivers message `m`, the
 * reference (loop_fuzz_reference.c). */
void check_routes(PumpObject *pump);
int python_takes(const struct message *m);

/* One input whose 4 bytes of configuration are not a RosPump's (loop_fuzz_pump.c). */
void fuzz_pump(const uint8_t *data, size_t size);
/* One input whose configuration's last byte is 0x80 or more (loop_fuzz_ros_pump.c). */
void fuzz_ros_pump(const uint8_t *data, size_t size);

#endif
