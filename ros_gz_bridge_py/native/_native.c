/* The module of the native data plane (docs/native.md): its types (one a file, _native.h),
 * the constants Python reads from here, defined once (the events of a loop's report, the names
 * of the foreign functions each type calls), the named structures the types return, and the
 * helpers the files share. */
#include "_native.h"

#include <string.h>

struct rgb_records rgb_records;

/* The records' fields (documented in _native.pyi), in the order the types fill them. */
#define FIELDS(name, ...) static PyStructSequence_Field name[] = {__VA_ARGS__, {NULL, NULL}}
#define F(name) {name, NULL}
FIELDS(pump_counts, F("received"), F("rate_limited"), F("published"), F("dropped"), F("skipped"),
       F("lost"), F("taken"), F("bytes_read"));
FIELDS(ros_pump_counts, F("received"), F("own_skipped"), F("rate_limited"), F("published"),
       F("take_errors"), F("send_failures"), F("lost"), F("bytes_read"));
FIELDS(handover, F("unrouted"), F("refused"), F("too_large"), F("grown"));
FIELDS(refused, F("sender"), F("msg_type"), F("payload"), F("status"));
FIELDS(too_large, F("sender"), F("msg_type"), F("items"), F("least"), F("size"));

#define RECORD(name, doc, fields) {"ros_gz_bridge_py.native._native." name, doc, fields, \
                                    sizeof fields / sizeof *fields - 1}
static PyStructSequence_Desc records[] = {
    RECORD("PumpCounts", "A Pump's counts so far.", pump_counts),
    RECORD("RosPumpCounts", "A RosPump's counts so far.", ros_pump_counts),
    RECORD("Handover", "What a Pump left to Python.", handover),
    RECORD("Refused", "A payload no program took.", refused),
    RECORD("TooLarge", "A payload refused as too large.", too_large),
};

PyObject *rgb_record(PyTypeObject *type, PyObject *values) {
    if (values == NULL) return NULL;
    PyObject *record = PyStructSequence_New(type);
    for (Py_ssize_t i = 0; record != NULL && i < PyTuple_GET_SIZE(values); i++)
        PyStructSequence_SetItem(record, i, Py_NewRef(PyTuple_GET_ITEM(values, i)));
    Py_DECREF(values);
    return record;
}

int rgb_functions(PyObject *addresses, const struct rgb_function *functions, void *table) {
    for (const struct rgb_function *f = functions; f->name != NULL; f++) {
        PyObject *address = PyDict_GetItemString(addresses, f->name); /* borrowed */
        void *pointer = address != NULL ? PyLong_AsVoidPtr(address) : NULL;
        if (pointer == NULL) { /* missing or 0; else not an address, and its error stands */
            if (!PyErr_Occurred())
                PyErr_Format(PyExc_ValueError, "functions: no address of %s", f->name);
            return -1;
        }
        memcpy((char *)table + f->offset, &pointer, sizeof pointer); /* a function pointer */
    }
    return 0;
}

/* Adds the names of `functions` to module `m` as the tuple `name`. */
static int add_names(PyObject *m, const char *name, const struct rgb_function *functions) {
    Py_ssize_t n = 0;
    while (functions[n].name != NULL) n++;
    PyObject *names = PyTuple_New(n);
    for (Py_ssize_t i = 0; names != NULL && i < n; i++) {
        PyObject *item = PyUnicode_FromString(functions[i].name);
        if (item == NULL) Py_CLEAR(names);
        else PyTuple_SET_ITEM(names, i, item);
    }
    int result = names != NULL ? PyModule_AddObjectRef(m, name, names) : -1;
    Py_XDECREF(names);
    return result;
}

uint8_t *rgb_copy(const void *p, size_t n) {
    uint8_t *copy = malloc(n ? n : 1);
    if (copy != NULL && n) memcpy(copy, p, n);
    return copy;
}

int64_t rgb_now_ns(clockid_t clock) {
    struct timespec t;
    clock_gettime(clock, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

int rgb_admit(int64_t *next_ns, int64_t period_ns) {
    if (period_ns <= 0) return 1;
    int64_t now = rgb_now_ns(CLOCK_MONOTONIC);
    if (*next_ns != INT64_MIN && now < *next_ns) return 0;
    /* on the schedule, or a fresh start after a pause */
    int on_time = *next_ns != INT64_MIN && now - *next_ns < period_ns;
    *next_ns = on_time ? *next_ns + period_ns : now + period_ns;
    return 1;
}

struct rgb_member *rgb_member_of(PyObject *object) {
    if (!PyObject_TypeCheck(object, &rgb_PumpType) && !PyObject_TypeCheck(object, &rgb_RosPumpType))
        return NULL;
    struct rgb_member *m = &((MemberObject *)object)->member;
    return m->hooks != NULL ? m : NULL;
}

int rgb_member_usable(const struct rgb_member *m, int idle, const char *what, const char *unset) {
    if (m->hooks == NULL) {
        PyErr_SetString(PyExc_RuntimeError, unset);
        return -1;
    }
    if (idle && m->running != NULL && atomic_load(m->running)) {
        PyErr_Format(PyExc_RuntimeError, "the %s's loop is running it", what);
        return -1;
    }
    return 0;
}

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, .m_name = "_native",
    .m_doc = "The native data plane of ros_gz_bridge_py (docs/native.md).", .m_size = -1,
};

PyMODINIT_FUNC PyInit__native(void) {
    PyTypeObject *types[] = {&rgb_ProgramType, &rgb_EncoderType, &rgb_PumpType, &rgb_RosPumpType,
                             &rgb_LoopType};
    PyTypeObject **made[] = {&rgb_records.pump_counts, &rgb_records.ros_pump_counts,
                             &rgb_records.handover, &rgb_records.refused, &rgb_records.too_large};
    PyObject *m = PyModule_Create(&module);
    if (m == NULL) return NULL;
    for (size_t i = 0; i < sizeof types / sizeof *types; i++)
        if (PyModule_AddType(m, types[i]) < 0) goto failed;
    for (size_t i = 0; i < sizeof made / sizeof *made; i++) {
        if (*made[i] == NULL) *made[i] = PyStructSequence_NewType(&records[i]);
        if (*made[i] == NULL || PyModule_AddType(m, *made[i]) < 0) goto failed;
    }
    if (PyModule_AddIntConstant(m, "EVENT_HANDED", RGB_EVENT_HANDED) < 0 ||
        PyModule_AddIntConstant(m, "EVENT_MONITOR", RGB_EVENT_MONITOR) < 0 ||
        PyModule_AddIntConstant(m, "EVENT_BROKEN", RGB_EVENT_BROKEN) < 0 ||
        add_names(m, "PUMP_FUNCTIONS", rgb_pump_functions) < 0 ||
        add_names(m, "ROS_PUMP_FUNCTIONS", rgb_ros_pump_functions) < 0)
        goto failed;
    return m;
failed:
    Py_DECREF(m);
    return NULL;
}
