/* The two transcoders' Python faces (docs/native.md §2-§6): Program, one pair's Gazebo -> ROS
 * transcoder (transcode.c), and Encoder, one pair's ROS -> Gazebo transcoder (encode.c), each
 * loaded once from the words program.py or encoder.py compiles. The pumps run them without
 * the GIL (rgb_program_of, rgb_encoder_of). */
#include "_native.h"

#include <structmember.h>

typedef struct {
    PyObject_HEAD
    struct rgb_program program;
    int32_t *words; /* schema then ops, owned */
    struct rgb_out out;
    Py_ssize_t steps; /* fields the last to_cdr read: its work, for the tests */
} ProgramObject;

static void program_dealloc(ProgramObject *self) {
    rgb_out_free(&self->out);
    PyMem_Free(self->words);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int program_init(ProgramObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {"schema", "ops", NULL};
    Py_buffer schema, ops;
    /* A pump may be reading the words with the GIL released: they are never replaced. */
    if (self->words != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "a Program is loaded once; make a new Program");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "y*y*", keywords, &schema, &ops)) return -1;
    int result = -1;
    if (schema.len % 4 || ops.len % 4) {
        PyErr_SetString(PyExc_ValueError, "schema and ops are int32 words");
        goto done;
    }
    size_t schema_len = (size_t)schema.len / 4, ops_len = (size_t)ops.len / 4;
    int32_t *words = PyMem_Malloc((schema_len + ops_len + 1) * 4);
    if (words == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    memcpy(words, schema.buf, (size_t)schema.len);
    memcpy(words + schema_len, ops.buf, (size_t)ops.len);
    const char *why = "";
    if (rgb_load(&self->program, words, schema_len, words + schema_len, ops_len, &why)) {
        PyMem_Free(words);
        PyErr_Format(PyExc_ValueError, "not a native program: %s", why);
        goto done;
    }
    self->words = words;
    result = 0;
done:
    PyBuffer_Release(&schema);
    PyBuffer_Release(&ops);
    return result;
}

static Py_ssize_t clamp_ssize(size_t n) {
    return n > (size_t)PY_SSIZE_T_MAX ? PY_SSIZE_T_MAX : (Py_ssize_t)n;
}

/* to_cdr(payload) -> (status, bytes, (items, least) for RGB_TOO_LARGE, or None) */
static PyObject *program_to_cdr(ProgramObject *self, PyObject *arg) {
    if (self->words == NULL) {
        PyErr_SetString(PyExc_ValueError, "program not loaded");
        return NULL;
    }
    Py_buffer payload;
    if (PyObject_GetBuffer(arg, &payload, PyBUF_SIMPLE)) return NULL;
    size_t steps = 0;
    enum rgb_status status = rgb_to_cdr_counted(&self->program, payload.buf, (size_t)payload.len,
                                                &self->out, &steps);
    PyBuffer_Release(&payload);
    self->steps = steps > PY_SSIZE_T_MAX ? PY_SSIZE_T_MAX : (Py_ssize_t)steps;
    PyObject *result;
    if (status == RGB_TOO_LARGE)
        result = Py_BuildValue("(i(nn))", (int)status, clamp_ssize(self->out.refused.items),
                               clamp_ssize(self->out.refused.least));
    else if (status != RGB_OK)
        result = Py_BuildValue("(iO)", (int)status, Py_None);
    else
        result = Py_BuildValue("(iy#)", 0, (const char *)self->out.data, (Py_ssize_t)self->out.len);
    rgb_out_trim(&self->out);
    return result;
}

static PyMethodDef program_methods[] = {
    {"to_cdr", (PyCFunction)program_to_cdr, METH_O,
     "to_cdr(payload) -> (status, cdr or None): 0 ok, 1 undecodable, 2 conversion, 3 fallback; "
     "4 too large, with (items, least bytes of one) for None"},
    {NULL, NULL, 0, NULL},
};

static PyMemberDef program_members[] = {
    {"steps", T_PYSSIZET, offsetof(ProgramObject, steps), READONLY,
     "the protobuf fields the last to_cdr read (its work)"},
    {NULL, 0, 0, 0, NULL},
};

static PyObject *program_kept_bytes(ProgramObject *self, void *closure) {
    (void)closure;
    return PyLong_FromSize_t(self->out.cap + self->out.scratch_cap);
}

static PyGetSetDef program_getset[] = {
    {"kept_bytes", (getter)program_kept_bytes, NULL,
     "the bytes of output buffer and scratch kept for the next to_cdr", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

PyTypeObject rgb_ProgramType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.Program",
    .tp_basicsize = sizeof(ProgramObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "One pair's Gazebo -> ROS transcoder (docs/native.md).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)program_init,
    .tp_dealloc = (destructor)program_dealloc,
    .tp_methods = program_methods,
    .tp_members = program_members,
    .tp_getset = program_getset,
};

typedef struct {
    PyObject_HEAD
    struct rgb_encoder encoder;
    int32_t *words; /* owned */
} EncoderObject;

static void encoder_dealloc(EncoderObject *self) {
    PyMem_Free(self->words);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static int encoder_init(EncoderObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {"words", NULL};
    Py_buffer words;
    /* A loop may be reading the words with the GIL released: they are never replaced. */
    if (self->words != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "an Encoder is loaded once; make a new Encoder");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "y*", keywords, &words)) return -1;
    int result = -1;
    if (words.len % 4) {
        PyErr_SetString(PyExc_ValueError, "an encoder is int32 words");
        goto done;
    }
    int32_t *copy = PyMem_Malloc((size_t)words.len + 4);
    if (copy == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    memcpy(copy, words.buf, (size_t)words.len);
    const char *why = "";
    if (rgb_encoder_load(&self->encoder, copy, (size_t)words.len / 4, &why)) {
        PyMem_Free(copy);
        PyErr_Format(PyExc_ValueError, "not a native encoder: %s", why);
        goto done;
    }
    self->words = copy;
    result = 0;
done:
    PyBuffer_Release(&words);
    return result;
}

/* to_pb(cdr) -> (status, bytes or None); the output buffer is the call's own, so channels
 * on several threads may share one encoder. */
static PyObject *encoder_to_pb(EncoderObject *self, PyObject *arg) {
    if (self->words == NULL) {
        PyErr_SetString(PyExc_ValueError, "encoder not loaded");
        return NULL;
    }
    Py_buffer cdr;
    if (PyObject_GetBuffer(arg, &cdr, PyBUF_SIMPLE)) return NULL;
    struct rgb_out out = {.data = NULL};
    enum rgb_status status = rgb_to_pb(&self->encoder, cdr.buf, (size_t)cdr.len, &out);
    PyBuffer_Release(&cdr);
    PyObject *result;
    if (status != RGB_OK) {
        result = Py_BuildValue("(iO)", (int)status, Py_None);
    } else {
        const char *data = out.len ? (const char *)out.data : ""; /* empty: no buffer */
        result = Py_BuildValue("(iy#)", 0, data, (Py_ssize_t)out.len);
    }
    rgb_out_free(&out);
    return result;
}

static PyMethodDef encoder_methods[] = {
    {"to_pb", (PyCFunction)encoder_to_pb, METH_O,
     "to_pb(cdr) -> (status, payload or None): 0 ok, 1 undecodable, 3 fallback"},
    {NULL, NULL, 0, NULL},
};

PyTypeObject rgb_EncoderType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "ros_gz_bridge_py.native._native.Encoder",
    .tp_basicsize = sizeof(EncoderObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "One pair's ROS -> Gazebo transcoder (docs/native.md §6).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)encoder_init,
    .tp_dealloc = (destructor)encoder_dealloc,
    .tp_methods = encoder_methods,
};

struct rgb_encoder *rgb_encoder_of(PyObject *object) {
    if (!PyObject_TypeCheck(object, &rgb_EncoderType)) return NULL;
    EncoderObject *encoder = (EncoderObject *)object;
    return encoder->words == NULL ? NULL : &encoder->encoder;
}

struct rgb_program *rgb_program_of(PyObject *object) {
    if (!PyObject_TypeCheck(object, &rgb_ProgramType)) return NULL;
    ProgramObject *program = (ProgramObject *)object;
    return program->words == NULL ? NULL : &program->program;
}
