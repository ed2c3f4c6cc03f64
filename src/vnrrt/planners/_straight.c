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
 * plan(grid, start, goal, planner, heatmap, config, sampler, stop, reference_length, seed,
 *      milestones, keep_tree)
 * solve(planner, start, goal, stop, reference_length, seed, milestones, keep_tree)
 *   vnrrt.planners.plan's and Planner.solve's arguments in their order (solve's first: the
 *   Planner): when they have the common form (see plan() and common_query() below) the same
 *   answer as answer()'s, else None, raising nothing: the caller then checks them in Python.
 *
 * bind(kernel_address, result_type, fields, config_type, planner_type)
 *   kernel_address: a numba cfunc's address, double f(const uint8 *, intp h, intp w, double
 *   sx, double sy, double gx, double gy); result_type: the PlanResult class; fields: the
 *   dict of a straight answer's shared fields (run.STRAIGHT), copied per result;
 *   config_type, planner_type: the PlannerConfig and Planner classes (of the common form).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <numpy/arrayscalars.h>

typedef double (*kernel_fn)(const uint8_t *, npy_intp, npy_intp, double, double, double, double);

static kernel_fn kernel = NULL;
static PyObject *result_type = NULL; /* PlanResult */
static PyObject *shared = NULL;      /* the fields every straight answer shares */
static PyObject *empty_args = NULL;  /* () for object.__new__ */
static PyObject *config_type = NULL; /* PlannerConfig */
static PyObject *planner_type = NULL; /* Planner */
static PyObject *zero = NULL;        /* 0.0: plan()'s setup_time */
static PyArray_Descr *uint8_descr = NULL; /* numpy's uint8 dtype object */

enum { PLANNER, PATH, COST, FIRST_COST, TIME_TO_FIRST, TIME_TO_STOP, TRACE_ITERATIONS,
       TRACE_COSTS, REFERENCE_LENGTH, TARGET_COST, SETUP_TIME, FALLBACK_UNIFORM, DICT, VALID,
       STRAIGHT, EPS, OCC, CONFIG, SAMPLER, NKEYS };
static const char *key_names[NKEYS] = {
    "planner", "path", "cost", "first_cost", "time_to_first", "time_to_stop",
    "trace_iterations", "trace_costs", "reference_length", "target_cost", "setup_time",
    "fallback_uniform", "__dict__", "_valid", "straight_first", "eps", "occ", "config", "sampler"};
static PyObject *keys[NKEYS];
enum { RRT_STAR, INITIAL, OPTIMAL, NSTRS };
static const char *str_values[NSTRS] = {"rrt_star", "initial", "optimal"};
static PyObject *strs[NSTRS];

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
    PyObject *type, *fields, *config, *planner;
    if (!PyArg_ParseTuple(args, "KO!O!O!O!:bind", &address, &PyType_Type, &type, &PyDict_Type,
                          &fields, &PyType_Type, &config, &PyType_Type, &planner))
        return NULL;
    if (address == 0) {
        PyErr_SetString(PyExc_ValueError, "bind: the kernel address is 0");
        return NULL;
    }
    Py_INCREF(type);
    Py_XSETREF(result_type, type);
    Py_INCREF(fields);
    Py_XSETREF(shared, fields);
    Py_INCREF(config);
    Py_XSETREF(config_type, config);
    Py_INCREF(planner);
    Py_XSETREF(planner_type, planner);
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
static int fill(PyObject *dict, PyObject *const *given, double d, double found, double *xy) {
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
    if (put_borrowed(dict, TARGET_COST, given[0]) < 0 ||
        put_borrowed(dict, PLANNER, given[1]) < 0 ||
        put_borrowed(dict, REFERENCE_LENGTH, given[2]) < 0 ||
        put_borrowed(dict, SETUP_TIME, given[3]) < 0 ||
        put_borrowed(dict, FALLBACK_UNIFORM, given[4]) < 0)
        return -1;
    return 0;
}

/* The PlanResult of the straight answer: object.__new__(PlanResult), its __dict__ the
 * filled copy (object.__setattr__: the frozen class's own __setattr__ refuses); given: the
 * objects target, planner, reference_length, setup_time, fallback (borrowed). */
static PyObject *straight_result(PyObject *const *given, double d, double found, double *xy) {
    PyObject *dict = PyDict_Copy(shared);
    if (dict == NULL)
        return NULL;
    PyObject *result = NULL;
    if (fill(dict, given, d, found, xy) == 0) {
        result = PyBaseObject_Type.tp_new((PyTypeObject *)result_type, empty_args, NULL);
        if (result != NULL && PyObject_GenericSetAttr(result, keys[DICT], dict) < 0)
            Py_CLEAR(result);
    }
    Py_DECREF(dict);
    return result;
}

/* The kernel's test of the segment xy on occ, timed: the straight answer's PlanResult when it
 * is free and its length meets target (INFINITY: any), else the tuple (d, seconds). given:
 * as straight_result's, given[0] (the target object) NULL when it is made here from target
 * (only for a result). */
static PyObject *tested(PyArrayObject *occ, double *xy, double target, PyObject **given) {
    double t0 = seconds();
    double d = kernel(PyArray_DATA(occ), PyArray_DIM(occ, 0), PyArray_DIM(occ, 1), xy[0], xy[1],
                      xy[2], xy[3]);
    double found = seconds() - t0;
    if (d < 0 || d > target)
        return Py_BuildValue("(dd)", d, found);
    if (given[0] != NULL)
        return straight_result(given, d, found, xy);
    PyObject *made = given[0] = PyFloat_FromDouble(target);
    PyObject *result = made == NULL ? NULL : straight_result(given, d, found, xy);
    Py_XDECREF(made);
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
    PyObject *given[5] = {args[5], args[6], args[7], args[8], args[9]};
    return tested(occ, xy, target, given);
}

/* plan()'s common form, recognised without the interpreter. Each check below answers 1 when
 * its argument has that form (then its value is stored), else 0: plan() then takes its
 * Python path, which checks every argument and raises its errors. None of them raises. */

/* v is the str s (s interned). */
static int is_str(PyObject *v, PyObject *s) {
    return v == s || (PyUnicode_CheckExact(v) && PyUnicode_Compare(v, s) == 0);
}

/* v is a float, an int (not a bool) or a numpy float64, as a double (float(v)). */
static int number(PyObject *v, double *out) {
    if (PyFloat_CheckExact(v)) {
        *out = PyFloat_AS_DOUBLE(v);
        return 1;
    }
    if (Py_IS_TYPE(v, &PyDoubleArrType_Type)) {
        *out = PyArrayScalar_VAL(v, Double);
        return 1;
    }
    if (!PyLong_CheckExact(v))
        return 0;
    *out = PyLong_AsDouble(v);
    if (*out == -1.0 && PyErr_Occurred()) {
        PyErr_Clear(); /* too large for a double: Python's float() raises it */
        return 0;
    }
    return 1;
}

/* start and goal each a tuple or list of two numbers (number()), their sum finite: xy is
 * (sx, sy, gx, gy) as api._floats makes it. */
static int points(PyObject *start, PyObject *goal, double *xy) {
    PyObject *p[2] = {start, goal};
    for (int k = 0; k < 2; k++) {
        if (!(PyTuple_CheckExact(p[k]) || PyList_CheckExact(p[k])) ||
            PySequence_Fast_GET_SIZE(p[k]) != 2)
            return 0;
        PyObject **items = PySequence_Fast_ITEMS(p[k]);
        if (!number(items[0], xy + 2 * k) || !number(items[1], xy + 2 * k + 1))
            return 0;
    }
    return isfinite(xy[0] + xy[1] + xy[2] + xy[3]);
}

/* v is an int >= 0 (not a bool). */
static int natural(PyObject *v) {
    if (!PyLong_CheckExact(v))
        return 0;
    int overflow;
    long long x = PyLong_AsLongLongAndOverflow(v, &overflow);
    return overflow > 0 || (overflow == 0 && x >= 0);
}

/* seed an int >= 0 or a tuple of them (api._seed_ok's fast cases). */
static int seed_ok(PyObject *seed) {
    if (PyLong_CheckExact(seed))
        return natural(seed);
    if (!PyTuple_CheckExact(seed))
        return 0;
    for (Py_ssize_t i = 0; i < PyTuple_GET_SIZE(seed); i++)
        if (!natural(PyTuple_GET_ITEM(seed, i)))
            return 0;
    return 1;
}

/* occ is used in place by the planners (api._occupancy): an exact ndarray of numpy's uint8
 * dtype object, 2-D, at least 2x2, C-contiguous. */
static int grid_ok(PyObject *grid) {
    if (!PyArray_CheckExact(grid))
        return 0;
    PyArrayObject *occ = (PyArrayObject *)grid;
    return PyArray_DESCR(occ) == uint8_descr && PyArray_NDIM(occ) == 2 &&
           PyArray_DIM(occ, 0) >= 2 && PyArray_DIM(occ, 1) >= 2 && PyArray_IS_C_CONTIGUOUS(occ);
}

/* config a PlannerConfig (not a subclass) already validated, with straight_first true and an
 * eps that is a float or an int: *eps its value. */
static int config_ok(PyObject *config, double *eps) {
    if (!Py_IS_TYPE(config, (PyTypeObject *)config_type))
        return 0;
    PyObject *dict = PyObject_GenericGetDict(config, NULL);
    if (dict == NULL || !PyDict_CheckExact(dict)) {
        PyErr_Clear();
        Py_XDECREF(dict);
        return 0;
    }
    /* borrowed: the frozen config's dict keeps them */
    PyObject *valid = PyDict_GetItemWithError(dict, keys[VALID]);
    PyObject *straight = valid == NULL ? NULL : PyDict_GetItemWithError(dict, keys[STRAIGHT]);
    PyObject *e = straight == NULL ? NULL : PyDict_GetItemWithError(dict, keys[EPS]);
    int ok = e != NULL && valid == Py_True && straight == Py_True &&
             PyFloat_CheckExact(e) != PyLong_CheckExact(e) && number(e, eps);
    PyErr_Clear(); /* a lookup's error, if any: Python's path */
    Py_DECREF(dict);
    return ok;
}

/* A query's common form (api._free_segment's): start and goal points(), stop 'initial' or
 * 'optimal' with a reference_length float or int, finite and >= 0 (optional for 'initial'),
 * seed_ok(), milestones () and keep_tree False. q: (start, goal, stop, reference_length, seed,
 * milestones, keep_tree); eps: the config's. Stores the points in xy and the stop bound in
 * *target (INFINITY: any length); *optimal: whether the stop rule is 'optimal'. */
static int common_query(PyObject *const *q, double eps, double *xy, double *target,
                        int *optimal) {
    PyObject *stop = q[2], *reference = q[3];
    double length = 0.0;
    if (q[6] != Py_False || !PyTuple_CheckExact(q[5]) || PyTuple_GET_SIZE(q[5]) != 0 ||
        !seed_ok(q[4]) || !points(q[0], q[1], xy))
        return 0;
    *optimal = is_str(stop, strs[OPTIMAL]);
    if (!*optimal && !is_str(stop, strs[INITIAL]))
        return 0;
    if (reference != Py_None) {
        if (PyFloat_CheckExact(reference) == PyLong_CheckExact(reference) ||
            !number(reference, &length) || !(length >= 0 && length < INFINITY))
            return 0;
    } else if (*optimal) {
        return 0; /* the reference is computed: Python's path */
    }
    *target = *optimal ? (1.0 + eps) * length : INFINITY;
    return 1;
}

/* The answer of a common query q (common_query()) on occ, given: planner, setup_time and
 * fallback (borrowed; see straight_result); None when q has another form. */
static PyObject *common_answer(PyArrayObject *occ, PyObject *const *q, double eps,
                               PyObject *planner, PyObject *setup_time, PyObject *fallback) {
    double xy[4], target;
    int optimal;
    if (!common_query(q, eps, xy, &target, &optimal))
        Py_RETURN_NONE;
    PyObject *given[5] = {optimal ? NULL : Py_None, planner, q[3], setup_time, fallback};
    return tested(occ, xy, target, given);
}

/* plan(grid, start, goal, planner, heatmap, config, sampler, stop, reference_length, seed,
 * milestones, keep_tree): its answer when the arguments have plan()'s common form (RRT*, no
 * heatmap or sampler, a validated config with straight_first, the grid used in place, a
 * common query: common_query()): the straight answer's PlanResult, or the tuple (d, seconds)
 * of a segment tested that does not answer; None when the arguments have another form or no
 * kernel is bound (plan() then checks them in Python). */
static PyObject *plan(PyObject *Py_UNUSED(self), PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 12) {
        PyErr_Format(PyExc_TypeError, "plan takes 12 arguments, got %zd", nargs);
        return NULL;
    }
    double eps;
    if (kernel == NULL || !is_str(args[3], strs[RRT_STAR]) || args[4] != Py_None ||
        args[6] != Py_None || !config_ok(args[5], &eps) || !grid_ok(args[0]))
        Py_RETURN_NONE;
    PyObject *q[7] = {args[1], args[2], args[7], args[8], args[9], args[10], args[11]};
    return common_answer((PyArrayObject *)args[0], q, eps, strs[RRT_STAR], zero, Py_False);
}

/* solve(planner, start, goal, stop, reference_length, seed, milestones, keep_tree):
 * Planner.solve's answer as plan()'s, for a Planner (not a subclass) whose grid is used in
 * place and whose config is validated with straight_first, its planner name a str, its
 * setup_time a float and its sampler's fallback_uniform a bool. */
static PyObject *solve(PyObject *Py_UNUSED(self), PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 8) {
        PyErr_Format(PyExc_TypeError, "solve takes 8 arguments, got %zd", nargs);
        return NULL;
    }
    if (kernel == NULL || !Py_IS_TYPE(args[0], (PyTypeObject *)planner_type))
        Py_RETURN_NONE;
    PyObject *dict = PyObject_GenericGetDict(args[0], NULL);
    if (dict == NULL || !PyDict_CheckExact(dict)) {
        PyErr_Clear();
        Py_XDECREF(dict);
        Py_RETURN_NONE;
    }
    static const int names[5] = {OCC, CONFIG, PLANNER, SETUP_TIME, SAMPLER};
    PyObject *v[5]; /* borrowed from the planner's dict */
    int found = 1;
    for (int i = 0; i < 5 && found; i++)
        found = (v[i] = PyDict_GetItemWithError(dict, keys[names[i]])) != NULL;
    PyErr_Clear();
    double eps;
    PyObject *fallback = NULL, *answer = NULL;
    if (found && PyUnicode_CheckExact(v[2]) && PyFloat_CheckExact(v[3]) && grid_ok(v[0]) &&
        config_ok(v[1], &eps)) {
        fallback = PyObject_GetAttr(v[4], keys[FALLBACK_UNIFORM]);
        PyErr_Clear();
    }
    if (fallback == Py_True || fallback == Py_False)
        answer = common_answer((PyArrayObject *)v[0], args + 1, eps, v[2], v[3], fallback);
    Py_XDECREF(fallback);
    Py_DECREF(dict);
    if (answer == NULL && !PyErr_Occurred())
        Py_RETURN_NONE;
    return answer;
}

static PyMethodDef methods[] = {
    {"bind", bind, METH_VARARGS,
     "bind(kernel_address, result_type, fields, config_type, planner_type): see the module."},
    {"answer", (PyCFunction)(void (*)(void))answer, METH_FASTCALL,
     "answer(occ, sx, sy, gx, gy, target, planner, reference_length, setup_time, fallback)"},
    {"solve", (PyCFunction)(void (*)(void))solve, METH_FASTCALL,
     "solve(planner, start, goal, stop, reference_length, seed, milestones, keep_tree)"},
    {"plan", (PyCFunction)(void (*)(void))plan, METH_FASTCALL,
     "plan(grid, start, goal, planner, heatmap, config, sampler, stop, reference_length, seed, "
     "milestones, keep_tree)"},
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
    for (int i = 0; i < NSTRS; i++) {
        strs[i] = PyUnicode_InternFromString(str_values[i]);
        if (strs[i] == NULL)
            return NULL;
    }
    uint8_descr = PyArray_DescrFromType(NPY_UINT8);
    empty_args = PyTuple_New(0);
    zero = PyFloat_FromDouble(0.0);
    if (uint8_descr == NULL || empty_args == NULL || zero == NULL)
        return NULL;
    return PyModule_Create(&module);
}
