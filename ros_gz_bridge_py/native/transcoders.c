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

/* One copy of the int32 words of buffers[0..n) (PyMem: the caller owns it; lens[i]: the words
 * of buffers[i]), released; NULL with a Python error (ValueError `not_words` where a buffer is
 * not whole words). */
static int32_t *words_of(Py_buffer *buffers, int n, size_t *lens, const char *not_words) {
    size_t total = 0, at = 0;
    int whole = 1;
    for (int i = 0; i < n; i++) {
        lens[i] = (size_t)buffers[i].len / 4;
        total += lens[i];
        whole = whole && buffers[i].len % 4 == 0;
    }
    int32_t *words = whole ? PyMem_Malloc((total + 1) * 4) : NULL;
    if (!whole) PyErr_SetString(PyExc_ValueError, not_words);
    else if (words == NULL) PyErr_NoMemory();
    for (int i = 0; i < n; i++) {
        if (words != NULL) memcpy(words + at, buffers[i].buf, lens[i] * 4);
        at += lens[i];
        PyBuffer_Release(&buffers[i]);
    }
    return words;
}

static int program_init(ProgramObject *self, PyObject *args, PyObject *kwds) {
    static char *keywords[] = {"schema", "ops", NULL};
    Py_buffer parts[2]; /* schema, ops */
    size_t lens[2];
    /* A pump may be reading the words with the GIL released: they are never replaced. */
    if (self->words != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "a Program is loaded once; make a new Program");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "y*y*", keywords, &parts[0], &parts[1]))
        return -1;
    int32_t *words = words_of(parts, 2, lens, "schema and ops are int32 words");
    const char *why = "";
    if (words != NULL && rgb_load(&self->program, words, lens[0], words + lens[0], lens[1], &why)) {
        PyMem_Free(words);
        PyErr_Format(PyExc_ValueError, "not a native program: %s", why);
        return -1;
    }
    self->words = words;
    return words != NULL ? 0 : -1;
}

/* (status, None), or (0, the output's bytes) when the status is RGB_OK. */
static PyObject *outcome(enum rgb_status status, const struct rgb_out *out) {
    if (status != RGB_OK) return Py_BuildValue("(iO)", (int)status, Py_None);
    const char *data = out->len ? (const char *)out->data : ""; /* empty: no buffer */
    return Py_BuildValue("(iy#)", 0, data, (Py_ssize_t)out->len);
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
    enum rgb_status status =
        rgb_to_cdr(&self->program, payload.buf, (size_t)payload.len, &self->out, &steps);
    PyBuffer_Release(&payload);
    self->steps = rgb_clamp(steps);
    PyObject *result;
    if (status == RGB_TOO_LARGE)
        result = Py_BuildValue("(i(nn))", (int)status, rgb_clamp(self->out.refused.items),
                               rgb_clamp(self->out.refused.least));
    else
        result = outcome(status, &self->out);
    rgb_trim(&self->out);
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
    Py_buffer buffer;
    size_t len;
    /* A loop may be reading the words with the GIL released: they are never replaced. */
    if (self->words != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "an Encoder is loaded once; make a new Encoder");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "y*", keywords, &buffer)) return -1;
    int32_t *words = words_of(&buffer, 1, &len, "an encoder is int32 words");
    const char *why = "";
    if (words != NULL && rgb_encoder_load(&self->encoder, words, len, &why)) {
        PyMem_Free(words);
        PyErr_Format(PyExc_ValueError, "not a native encoder: %s", why);
        return -1;
    }
    self->words = words;
    return words != NULL ? 0 : -1;
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
    PyObject *result = outcome(status, &out);
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
