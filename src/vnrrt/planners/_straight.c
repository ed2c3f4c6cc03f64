/* vnrrt.planners._straight: the answer to a query whose straight start-goal segment is free,
 * made in one C call (see vnrrt/planners/native.py, which binds it, and run.free_answer, the
 * Python function of the same semantics used where this module is not built).
 *
 * answer(occ, sx, sy, gx, gy, target, planner, reference_length, setup_time, fallback)
 *   occ: (H, W) C-contiguous uint8 numpy array (nonzero = obstacle, occ[y, x]); sx .. gy:
 *   numbers, pixels (converted to double; the planners pass floats); target: a number or None
 *   (the stop bound); the last four go into the result as they are. Calls the bound kernel
 *   (vnrrt.planners.core.query_test_at, compiled by numba as a C function) and times it on
 *   the clock of time.perf_counter (CPython's own function, so on every platform).
 *   Returns the PlanResult of the straight answer when the segment is free and its length d
 *   meets target (None: any), else the tuple (d, seconds) as run.straight_test returns it
 *   (d = -1: blocked; -2: an endpoint touches an obstacle or the border). The seconds are the
 *   kernel call's; run.straight_test's also hold numba's dispatch (~0.5 us).
 *
 * bind(kernel_address, result_type, fields)
 *   kernel_address: a numba cfunc's address, double f(const uint8 *, intp h, intp w, double
 *   sx, double sy, double gx, double gy); result_type: the PlanResult class; fields: the
 *   dict of a straight answer's shared fields (run.STRAIGHT), copied per result.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <string.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

typedef double (*kernel_fn)(const uint8_t *, npy_intp, npy_intp, double, double, double, double);

static kernel_fn kernel = NULL;
static PyObject *result_type = NULL; /* PlanResult */
static PyObject *shared = NULL;      /* the fields every straight answer shares */
static PyObject *empty_args = NULL;  /* () for object.__new__ */

enum { PLANNER, PATH, COST, FIRST_COST, TIME_TO_FIRST, TIME_TO_STOP, TRACE_ITERATIONS,
       TRACE_COSTS, REFERENCE_LENGTH, TARGET_COST, SETUP_TIME, FALLBACK_UNIFORM, DICT, NKEYS };
static const char *key_names[NKEYS] = {
    "planner", "path", "cost", "first_cost", "time_to_first", "time_to_stop",
    "trace_iterations", "trace_costs", "reference_length", "target_cost", "setup_time",
    "fallback_uniform", "__dict__"};
static PyObject *keys[NKEYS];

/* Seconds on the clock of time.perf_counter (its own C function). */
static double seconds(void) {
#if PY_VERSION_HEX >= 0x030D0000
    PyTime_t t;
    if (PyTime_PerfCounterRaw(&t) < 0)
        return 0.0; /* not reached: perf_counter's clock was checked when Python started */
    return PyTime_AsSecondsDouble(t);
#else
    return _PyTime_AsSecondsDouble(_PyTime_GetPerfCounter());
#endif
}

static PyObject *bind(PyObject *Py_UNUSED(self), PyObject *args) {
    unsigned long long address;
    PyObject *type, *fields;
    if (!PyArg_ParseTuple(args, "KO!O!:bind", &address, &PyType_Type, &type, &PyDict_Type,
                          &fields))
        return NULL;
    if (address == 0) {
        PyErr_SetString(PyExc_ValueError, "bind: the kernel address is 0");
        return NULL;
    }
    Py_INCREF(type);
    Py_XSETREF(result_type, type);
    Py_INCREF(fields);
    Py_XSETREF(shared, fields);
    kernel = (kernel_fn)(uintptr_t)address;
    Py_RETURN_NONE;
}

/* A new 1-D or 2-D array of dtype type holding the bytes at src; NULL on an error. */
static PyObject *filled(int ndim, npy_intp *dims, int type, const void *src, size_t bytes) {
    PyObject *a = PyArray_SimpleNew(ndim, dims, type);
    if (a != NULL)
        memcpy(PyArray_DATA((PyArrayObject *)a), src, bytes);
    return a;
}

/* dict[keys[key]] = value, then value's reference dropped (a new one, or NULL after an error:
 * then -1, as on a failed set). */
static int put(PyObject *dict, int key, PyObject *value) {
    if (value == NULL)
        return -1;
    int status = PyDict_SetItem(dict, keys[key], value);
    Py_DECREF(value);
    return status;
}

/* dict[keys[key]] = value, a borrowed reference. */
static int put_borrowed(PyObject *dict, int key, PyObject *value) {
    return PyDict_SetItem(dict, keys[key], value);
}

/* The fields of the straight answer in dict (a copy of the shared ones): 0, or -1 on an error
 * (each step runs only after the ones before succeeded). */
static int fill(PyObject *dict, PyObject *const *args, double d, double found, double *xy) {
    npy_intp path_dims[2] = {2, 2}, one = 1;
    int64_t root = 0;
    if (put(dict, PATH, filled(2, path_dims, NPY_FLOAT64, xy, 4 * sizeof(double))) < 0 ||
        put(dict, TRACE_ITERATIONS, filled(1, &one, NPY_INT64, &root, sizeof root)) < 0 ||
        put(dict, TRACE_COSTS, filled(1, &one, NPY_FLOAT64, &d, sizeof d)) < 0)
        return -1;
    PyObject *cost = PyFloat_FromDouble(d); /* one float object for both fields, as in Python */
    if (cost == NULL || put_borrowed(dict, FIRST_COST, cost) < 0) {
        Py_XDECREF(cost);
        return -1;
    }
    if (put(dict, COST, cost) < 0)
        return -1;
    PyObject *time = PyFloat_FromDouble(found);
    if (time == NULL || put_borrowed(dict, TIME_TO_STOP, time) < 0) {
        Py_XDECREF(time);
        return -1;
    }
    if (put(dict, TIME_TO_FIRST, time) < 0)
        return -1;
    if (put_borrowed(dict, PLANNER, args[6]) < 0 ||
        put_borrowed(dict, REFERENCE_LENGTH, args[7]) < 0 ||
        put_borrowed(dict, TARGET_COST, args[5]) < 0 ||
        put_borrowed(dict, SETUP_TIME, args[8]) < 0 ||
        put_borrowed(dict, FALLBACK_UNIFORM, args[9]) < 0)
        return -1;
    return 0;
}

/* The PlanResult of the straight answer: object.__new__(PlanResult), its __dict__ the
 * filled copy (object.__setattr__: the frozen class's own __setattr__ refuses). */
static PyObject *straight_result(PyObject *const *args, double d, double found, double *xy) {
    PyObject *dict = PyDict_Copy(shared);
    if (dict == NULL)
        return NULL;
    PyObject *result = NULL;
    if (fill(dict, args, d, found, xy) == 0) {
        result = PyBaseObject_Type.tp_new((PyTypeObject *)result_type, empty_args, NULL);
        if (result != NULL && PyObject_GenericSetAttr(result, keys[DICT], dict) < 0)
            Py_CLEAR(result);
    }
    Py_DECREF(dict);
    return result;
}

static PyObject *answer(PyObject *Py_UNUSED(self), PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 10) {
        PyErr_Format(PyExc_TypeError, "answer takes 10 arguments, got %zd", nargs);
        return NULL;
    }
    if (kernel == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "answer: no kernel bound (call bind first)");
        return NULL;
    }
    PyArrayObject *occ = (PyArrayObject *)args[0];
    if (!PyArray_CheckExact(args[0]) || PyArray_TYPE(occ) != NPY_UINT8 ||
        PyArray_NDIM(occ) != 2 || !PyArray_IS_C_CONTIGUOUS(occ)) {
        PyErr_SetString(PyExc_TypeError, "answer: occ must be a C-contiguous 2-D uint8 ndarray");
        return NULL;
    }
    double xy[4];
    for (int i = 0; i < 4; i++) {
        xy[i] = PyFloat_AsDouble(args[1 + i]);
        if (xy[i] == -1.0 && PyErr_Occurred())
            return NULL;
    }
    double target = INFINITY;
    if (args[5] != Py_None) {
        target = PyFloat_AsDouble(args[5]);
        if (target == -1.0 && PyErr_Occurred())
            return NULL;
    }
    double t0 = seconds();
    double d = kernel(PyArray_DATA(occ), PyArray_DIM(occ, 0), PyArray_DIM(occ, 1), xy[0], xy[1],
                      xy[2], xy[3]);
    double found = seconds() - t0;
    if (d < 0 || d > target)
        return Py_BuildValue("(dd)", d, found);
    return straight_result(args, d, found, xy);
}

static PyMethodDef methods[] = {
    {"bind", bind, METH_VARARGS, "bind(kernel_address, result_type, fields): see the module."},
    {"answer", (PyCFunction)(void (*)(void))answer, METH_FASTCALL,
     "answer(occ, sx, sy, gx, gy, target, planner, reference_length, setup_time, fallback)"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {
    .m_base = PyModuleDef_HEAD_INIT,
    .m_name = "_straight",
    .m_doc = "The free straight segment's answer in one C call.",
    .m_size = -1,
    .m_methods = methods,
};

PyMODINIT_FUNC PyInit__straight(void) {
    import_array();
    for (int i = 0; i < NKEYS; i++) {
        keys[i] = PyUnicode_InternFromString(key_names[i]);
        if (keys[i] == NULL)
            return NULL;
    }
    empty_args = PyTuple_New(0);
    if (empty_args == NULL)
        return NULL;
    return PyModule_Create(&module);
}
