/* The per-message loop of a native Gazebo -> ROS channel (pump.c, docs/native.md §5). */
#ifndef RGB_PUMP_H
#define RGB_PUMP_H

#include <Python.h>

#include "encode.h"
#include "transcode.h"

/* Adds the Pump type to the module; -1 on error. */
int pump_register(PyObject *module);

/* Adds the RosPump type (ros_pump.c) to the module; -1 on error. */
int ros_pump_register(PyObject *module);

/* The loaded encoder of an Encoder object, or NULL when `object` is not one. */
struct rgb_encoder *native_encoder_of(PyObject *object);

/* The loaded program of a Program object, or NULL when `object` is not one. */
struct rgb_program *native_program_of(PyObject *object);

/* Reads the `count` function addresses of the sequence `functions` (pump.py, ros_pump.py
 * resolve them) into `out`; -1 with a Python error unless it holds exactly that many, none null. */
int native_addresses(PyObject *functions, void **out, Py_ssize_t count);

#endif
