/* The native Gazebo -> ROS channels: each one's Pump (pump.c) and the loop that runs them all
 * (loop.c), docs/native.md §5. */
#ifndef RGB_PUMP_H
#define RGB_PUMP_H

#include <Python.h>
#include <stdatomic.h>
#include <stdint.h>

#include "encode.h"
#include "transcode.h"

typedef struct PumpObject PumpObject;

/* Adds the Pump type to the module; -1 on error. */
int pump_register(PyObject *module);

/* Adds the Loop type (loop.c) to the module; -1 on error. */
int loop_register(PyObject *module);

/* Adds the RosPump type (ros_pump.c) to the module; -1 on error. */
int ros_pump_register(PyObject *module);

/* The loaded encoder of an Encoder object, or NULL when `object` is not one. */
struct rgb_encoder *native_encoder_of(PyObject *object);

/* The loaded program of a Program object, or NULL when `object` is not one. */
struct rgb_program *native_program_of(PyObject *object);

/* The initialised Pump `object` is, or NULL when it is not one. */
PumpObject *native_pump_of(PyObject *object);

/* Reads the `count` function addresses of the sequence `functions` (pump.py, ros_pump.py
 * resolve them) into `out`; -1 with a Python error unless it holds exactly that many, none null. */
int native_addresses(PyObject *functions, void **out, Py_ssize_t count);

/* ---- what the loop calls on a pump (GIL released, from the loop's thread only) ---------- */

/* The descriptor libzmq signals when `sock` has commands to process, or -1. */
int pump_zmq_fd(PumpObject *pump, void *sock);
/* Whether `monitor` (a PAIR socket: asking ZMQ_EVENTS prefetches nothing) has an event. */
int pump_monitor_ready(PumpObject *pump, void *monitor);
/* Reads up to `budget` messages of `sock` into the pump's queue (or its hand-over to Python):
 * 1 when a read found the socket empty, 0 when the budget ran out first, -1 when the socket
 * cannot be read (its context terminated, or it is closed). */
int pump_read(PumpObject *pump, void *sock, int budget);
/* Transcodes and publishes up to `budget` queued messages, until `slice_end` (CLOCK_MONOTONIC). */
void pump_deliver(PumpObject *pump, int budget, int64_t slice_end);
/* Messages queued; messages handed to Python and not yet taken; messages ever read. */
size_t pump_queued(const PumpObject *pump);
size_t pump_handed(const PumpObject *pump);
unsigned long long pump_taken(const PumpObject *pump);
/* Tells the pump which loop runs it (`running` is set while the loop runs without the GIL,
 * when Python may not change the pump); -1 when another loop already does. */
int pump_attach(PumpObject *pump, const atomic_int *running);
void pump_detach(PumpObject *pump);

#endif
