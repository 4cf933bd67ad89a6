/* libFuzzer target of the native channels' input handling, outside the transcoders (which
 * transcode_fuzz.c and encode_fuzz.c fuzz alone): a Gazebo -> ROS channel's pump
 * (ros_gz_bridge_py/native/pump_loop.c, pump.c) and a ROS -> Gazebo channel's (ros_pump_loop.c,
 * ros_pump.c), built with AddressSanitizer and UndefinedBehaviorSanitizer
 * (tests/unit/native/test_fuzz.py, `make fuzz`).
 *
 * The extension is linked in whole and Python embedded: a pump is made, taught and read through
 * its Python methods, as the bridge does, and turned through its loop hooks (rgb_pump_hooks,
 * rgb_ros_pump_hooks) as the Loop does, without a socket: the ZeroMQ, rcl and rmw functions it
 * is given are this file's, reading the messages of the input. The frames a Pump hands back are
 * judged by the real Python reader (tests/unit/native/loop_fuzz_host.py: NativeReader and its
 * socket owner), which teaches the pump its routes, as in the bridge. This file embeds Python
 * and reads the configuration; loop_fuzz_pump.c (with loop_fuzz_zmq.c, its fake socket, and
 * loop_fuzz_reference.c, the Python reader's verdicts) runs a Pump, loop_fuzz_ros_pump.c a
 * RosPump.
 *
 * Input: 4 bytes of configuration, then operations, each an opcode byte (modulo 8). A literal
 * below is a byte below 0x70 (that many bytes follow) or from 0x70 on (a 2-byte little-endian
 * length follows, then the bytes). The configuration's last byte below 0x80: a Pump (its
 * program, the queue's capacity and byte bound, max_rate, the monitor, the watched size, the
 * loop guard's digests; after each turn that published, the guard's is_own is asked of the
 * last publication's bytes, and of other bytes; and 0x20, whether the pump is the peer of a
 * reader pump (Pump.share) that reads the socket and is turned instead):
 *   0 MESSAGE  a frame count (1-18), then each frame: a literal, or from 0x80 on a frame of the
 *              dictionary (the topic, topics it prefixes, senders, the program's spellings,
 *              other types, a valid payload, a flood sender, a large payload). The fake SUB
 *              socket keeps it only when its first frame starts with the topic, as ZeroMQ;
 *   1 TURN     a byte: the message budget (1-8), the descriptors that fired, an error event;
 *   2 TAKE     take_handed, checked, and the unrouted frames judged by the Python reader;
 *   3 FLOOD    a count (1-64, or from 0xf0 on enough to fill the route table): that many
 *              distinct senders learned, as the reader learns them (the table fills and evicts);
 *   4 FORGET, 5 WATCH (a size), 6 PUBLISH_FAILS (toggles rcl's answer), 7 BREAK (the next
 *              read fails).
 * From 0x80 on: a RosPump (its encoder, 1-4 spellings sharing encoders or types, max_rate):
 *   0 a CDR message: its publisher (and whether rcl tells of it), a literal;  1 TURN as above;
 *   2 take_handed;  3 set_active (a mask of spellings);  4 ignore (a mask of publishers, two of
 *   them without a GID);  5 the next sends fail (which, how many, the errno);  6 send from
 *   Python (a spelling, a literal of at most 16 bytes);  7 the next take fails.
 *
 * A model of each pump predicts every message's fate: for a Pump, from the routes the pump holds
 * before a turn, the queue's drops and the program's output; for a RosPump, from the publishers
 * ignored, the spellings active and each encoder's output. The target aborts where the pump
 * differs: a message handed back, queued, skipped, dropped, published, refused, sent or counted
 * otherwise, a frame, payload or CDR message changed, a ZeroMQ message leaked or closed twice, a
 * loop event wrong, and where a Pump takes or skips natively a message that the Python reader,
 * the reference, would not deliver or would. */
#include "loop_fuzz.h"

PyMODINIT_FUNC PyInit__native(void);

PyObject *module, *host, *host_module;

PyObject *call(PyObject *object, const char *name, const char *format, ...) {
    va_list args;
    va_start(args, format);
    PyObject *method = PyObject_GetAttrString(object, name);
    PyObject *argv = method == NULL ? NULL : Py_VaBuildValue(format, args);
    va_end(args);
    PyObject *result = argv == NULL ? NULL : PyObject_CallObject(method, argv);
    Py_XDECREF(method);
    Py_XDECREF(argv);
    if (result == NULL) {
        PyErr_Print();
        CHECK(!"a Python call failed");
    }
    return result;
}

static void init_python(void) {
    /* The venv's ROS wheels re-execute the interpreter at start to set the library path: this
     * process loads no ROS library, and is not to be replaced. */
    setenv("_ROS_WHEELS_BOOTSTRAP_COMPLETE", "1", 0);
    /* Python's objects from malloc: the sanitizers see them, and LeakSanitizer the pointers in
     * them (pymalloc's arenas are mapped memory it does not scan). */
    PyPreConfig preconfig;
    PyPreConfig_InitPythonConfig(&preconfig);
    preconfig.allocator = PYMEM_ALLOCATOR_MALLOC;
    PyStatus status = Py_PreInitialize(&preconfig);
    if (PyStatus_Exception(status)) Py_ExitStatusException(status);
    PyConfig config;
    PyConfig_InitPythonConfig(&config);
    config.install_signal_handlers = 0;
    config.parse_argv = 0;
    /* The venv's interpreter as the program: its site-packages, as the bridge has them. */
    status = PyConfig_SetBytesString(&config, &config.program_name, FUZZ_PYTHON);
    if (!PyStatus_Exception(status)) status = Py_InitializeFromConfig(&config);
    PyConfig_Clear(&config);
    if (PyStatus_Exception(status)) Py_ExitStatusException(status);
    PyObject *modules = PyImport_GetModuleDict();
    module = PyInit__native();
    CHECK(module != NULL);
    /* The extension under test is this binary's: the package's own module is never loaded. */
    CHECK(PyDict_SetItemString(modules, "ros_gz_bridge_py.native._native", module) == 0);
    PyObject *path = PySys_GetObject("path");
    const char *dirs[] = {FUZZ_ROOT "/tests/unit/native", FUZZ_ROOT};
    for (size_t i = 0; i < sizeof dirs / sizeof *dirs; i++) {
        PyObject *dir = PyUnicode_FromString(dirs[i]);
        CHECK(dir != NULL && PyList_Insert(path, 0, dir) == 0);
        Py_DECREF(dir);
    }
    host_module = PyImport_ImportModule("loop_fuzz_host");
    if (host_module == NULL) PyErr_Print();
    CHECK(host_module != NULL);
    Py_DECREF(call(host_module, "quiet", "()"));
    host = call(host_module, "Host", "()");
}

PyObject *function_addresses(const struct rgb_function *functions, const void *table) {
    PyObject *addresses = PyDict_New();
    CHECK(addresses != NULL);
    for (const struct rgb_function *f = functions; f->name != NULL; f++) {
        void *pointer;
        memcpy(&pointer, (const char *)table + f->offset, sizeof pointer);
        PyObject *address = PyLong_FromVoidPtr(pointer);
        CHECK(address != NULL && PyDict_SetItemString(addresses, f->name, address) == 0);
        Py_DECREF(address);
    }
    return addresses;
}

int bytes_equal(PyObject *object, const struct frame *f) {
    return PyBytes_Check(object) && (size_t)PyBytes_GET_SIZE(object) == f->size &&
           !memcmp(PyBytes_AS_STRING(object), f->data, f->size);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (module == NULL) init_python();
    if (size < 4) return 0;
    if (data[3] & 0x80) {
        fuzz_ros_pump(data, size);
        return 0;
    }
    fuzz_pump(data, size);
    return 0;
}
