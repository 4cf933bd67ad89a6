/* The Python side's part of fuzz/loop_fuzz.c's Gazebo -> ROS half (loop_fuzz_pump.c): the pump's
 * routes checked whole, and the Python reader's verdict on a message, the reference the model
 * checks the pump's fate of it against. */
#include "loop_fuzz.h"

/* The routes as the pump holds them: checked whole, and read for the model. */
void check_routes(PumpObject *pump) {
    CHECK(pump->nroutes >= 0 && pump->nroutes <= 1024);
    for (int i = 0; i < pump->nroutes; i++) {
        const struct route *r = &pump->routes[i];
        CHECK(r->program >= -1 && r->program < pump->nprograms);
        /* found under its own index: no route twice (the newest few: a full check is slow) */
        if (i + 16 >= pump->nroutes)
            CHECK(pump_find_route(pump, r->sender, r->sender_len, r->type, r->type_len) == i);
        if (r->program >= 0)
            CHECK(pump->programs[r->program].type_len == r->type_len &&
                  !memcmp(pump->programs[r->program].type, r->type, r->type_len));
    }
}

static PyObject *frames_list(const struct message *m, int n) {
    PyObject *list = PyList_New(n);
    CHECK(list != NULL);
    for (int k = 0; k < n; k++)
        PyList_SET_ITEM(list, k, PyBytes_FromStringAndSize((char *)m->frames[k].data,
                                                            (Py_ssize_t)m->frames[k].size));
    return list;
}

int python_takes(const struct message *m) {
    PyObject *frames = frames_list(m, m->n);
    PyObject *takes = call(host, "takes", "(O)", frames);
    int result = PyObject_IsTrue(takes);
    Py_DECREF(takes);
    Py_DECREF(frames);
    return result;
}
