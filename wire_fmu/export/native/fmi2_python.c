/*
 * wire_fmu's FMI 2.0 co-simulation binary: every FMI call of a host is
 * forwarded to the FMU's Python facade (wire_fmu.export.facade.CoreFacade).
 *
 * Built from this source by wire_fmu.export.native for the Python that
 * builds the FMU, and packed as binaries/<platform>/<modelIdentifier>.so.
 *
 * What it guarantees, and why it exists (it replaces the prebuilt wrapper
 * that pythonfmu ships):
 *
 *  - Reference ownership is exact. Every PyObject it keeps (the facade
 *    instance, FMU states, the strings handed out by fmi2GetString) is a
 *    strong reference released exactly once, under the GIL. The shipped
 *    wrapper released the script module's borrowed __dict__ on every
 *    instantiation and released an instance twice after any Python
 *    exception (once in its error path, once in fmi2FreeInstance); both
 *    corrupt the heap of the host process.
 *  - A Python exception is fmi2Error, never fmi2Fatal: the instance stays
 *    alive, so a master may restore a saved state or free it. Its message
 *    reaches the host's logger once (the facade's own report, else the
 *    exception's text). fmi2Fatal is left for a facade that cannot be
 *    created at all (then fmi2Instantiate returns NULL).
 *  - do_step returning False is fmi2Discard (the unit refused the step).
 *  - A KeyboardInterrupt raised inside the facade is handed back to a Python
 *    host with PyErr_SetInterrupt(), so Ctrl-C interrupts the host, not the
 *    unit.
 *  - The interpreter is never finalised by this library. In a Python host
 *    the host owns it; in a C host this library starts it once (with
 *    Py_InitializeEx(0): no signal handlers of its own) and leaves it to
 *    the end of the process, since finalising an interpreter from a
 *    library destructor races the host's own exit.
 *  - Messages are escaped for the logger's printf-style format.
 *  - A host thread that has no Python thread state gets one on its first
 *    call and keeps it (enter_python): PyGILState_Ensure alone makes and
 *    frees a thread state, with its frame stack, on every call from such a
 *    thread (every call of a C++ host's worker threads, libcosim's among
 *    them). One thread state stays per host thread that ever called in.
 *
 * The binary is not linked against libpython: in a Python host the
 * interpreter's symbols are already loaded; a C host preloads libpython
 * (docs/interop.md).
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <ctype.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#define FACADE_FILE "wire_fmu_facade.txt"
#define MAX_LINE 4096

typedef struct {
    char *name;
    char *resources;
    char *guid;
    fmi2CallbackFunctions callbacks;
    int logging_on;
    PyObject *instance; /* the facade, a strong reference */
    PyObject *strings;  /* bytes handed out by the last fmi2GetString */
    int reported;       /* messages of status Error or worse logged in this call */
    double last_time;   /* the unit's time after its last step (the start of a refused one) */
    int refused;        /* the last step was refused: the unit asks to end the simulation */
} Component;

static pthread_mutex_t start_lock = PTHREAD_MUTEX_INITIALIZER;

/* Take the GIL, as PyGILState_Ensure (release with PyGILState_Release). A thread
   without a Python thread state gets one that it keeps: a second Ensure, never
   released, holds it, so that its later calls only take and release the GIL. */
static PyGILState_STATE enter_python(void)
{
    int fresh = PyGILState_GetThisThreadState() == NULL;
    PyGILState_STATE gil = PyGILState_Ensure();
    if (fresh)
        (void)PyGILState_Ensure();
    return gil;
}

/* ------------------------------------------------------------------------- */
/* logging                                                                    */

static char *escaped(const char *text)
{
    size_t n = strlen(text), extra = 0;
    for (size_t i = 0; i < n; ++i)
        extra += text[i] == '%';
    char *out = malloc(n + extra + 1);
    if (out == NULL)
        return NULL;
    char *p = out;
    for (size_t i = 0; i < n; ++i) {
        *p++ = text[i];
        if (text[i] == '%')
            *p++ = '%';
    }
    *p = '\0';
    return out;
}

static const char *category_of(fmi2Status status)
{
    switch (status) {
    case fmi2Warning: return "logStatusWarning";
    case fmi2Discard: return "logStatusDiscard";
    case fmi2Error: return "logStatusError";
    case fmi2Fatal: return "logStatusFatal";
    default: return "logAll";
    }
}

static void log_to_host(const fmi2CallbackFunctions *callbacks, const char *name, int logging_on,
                        fmi2Status status, const char *category, const char *message)
{
    if (callbacks == NULL || callbacks->logger == NULL)
        return;
    if (status == fmi2OK && !logging_on)
        return; /* fmi2Warning and worse always reach the host */
    char *text = escaped(message);
    callbacks->logger(callbacks->componentEnvironment, name, status,
                      category ? category : category_of(status), text ? text : "(out of memory)");
    free(text);
}

static void logf_component(Component *c, fmi2Status status, const char *format, ...)
{
    char message[MAX_LINE];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (status >= fmi2Error)
        c->reported++;
    log_to_host(&c->callbacks, c->name, c->logging_on, status, NULL, message);
}

/* obj.<name>, a new reference or NULL. The name is interned first: the class's attribute
 * cache knows a name by its object, so the fresh string PyObject_GetAttrString makes
 * misses it on every call and the lookup walks the whole class hierarchy (counted, some
 * 500 machine instructions more per lookup; every call makes two). */
static PyObject *attribute(PyObject *obj, const char *name)
{
    PyObject *key = PyUnicode_InternFromString(name);
    if (key == NULL)
        return NULL;
    PyObject *value = PyObject_GetAttr(obj, key);
    Py_DECREF(key);
    return value;
}

/* Forward the facade's queued messages (pythonfmu LogMsg: status, category, msg). */
static void drain_log_queue(Component *c)
{
    PyObject *queue = attribute(c->instance, "log_queue");
    if (queue == NULL || !PyList_Check(queue)) {
        Py_XDECREF(queue);
        PyErr_Clear();
        return;
    }
    Py_ssize_t n = PyList_GET_SIZE(queue);
    for (Py_ssize_t i = 0; i < n; ++i) {
        PyObject *item = PyList_GET_ITEM(queue, i); /* borrowed */
        PyObject *status = PyObject_GetAttrString(item, "status");
        PyObject *category = PyObject_GetAttrString(item, "category");
        PyObject *msg = PyObject_GetAttrString(item, "msg");
        long level = status ? PyLong_AsLong(status) : (long)fmi2Error;
        const char *cat = (category && PyUnicode_Check(category)) ? PyUnicode_AsUTF8(category) : NULL;
        const char *text = (msg && PyUnicode_Check(msg)) ? PyUnicode_AsUTF8(msg) : NULL;
        PyErr_Clear();
        if (level < fmi2OK || level > fmi2Fatal)
            level = fmi2Error;
        if (level >= fmi2Error)
            c->reported++;
        log_to_host(&c->callbacks, c->name, c->logging_on, (fmi2Status)level, cat,
                    text ? text : "(unreadable message)");
        Py_XDECREF(status);
        Py_XDECREF(category);
        Py_XDECREF(msg);
    }
    if (PyList_SetSlice(queue, 0, n, NULL) != 0)
        PyErr_Clear();
    Py_DECREF(queue);
}

/* Turn the pending Python exception into a message; return fmi2Error. */
static fmi2Status exception_status(Component *c, const char *fmi_name)
{
    int interrupted = PyErr_ExceptionMatches(PyExc_KeyboardInterrupt);
    PyObject *type, *value, *traceback;
    PyErr_Fetch(&type, &value, &traceback);
    PyErr_NormalizeException(&type, &value, &traceback);
    if (interrupted) {
        PyErr_SetInterrupt(); /* the host's Python sees Ctrl-C at its next check */
        logf_component(c, fmi2Error, "%s: interrupted", fmi_name);
    } else if (c->reported == 0) { /* the facade did not say why: say it here */
        PyObject *text = value ? PyObject_Str(value) : NULL;
        const char *what = text ? PyUnicode_AsUTF8(text) : NULL;
        const char *kind = type ? ((PyTypeObject *)type)->tp_name : "exception";
        PyErr_Clear();
        logf_component(c, fmi2Error, "%s failed: %s: %s", fmi_name, kind, what ? what : "");
        Py_XDECREF(text);
    }
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(traceback);
    return fmi2Error;
}

/* ------------------------------------------------------------------------- */
/* calling the facade                                                         */

/* Call c->instance.<method>(*args); args is consumed. A new reference or NULL. */
static PyObject *call(Component *c, const char *method, PyObject *args)
{
    c->reported = 0;
    PyObject *result = NULL;
    if (args != NULL) {
        PyObject *bound = attribute(c->instance, method);
        if (bound != NULL) {
            result = PyObject_CallObject(bound, args);
            Py_DECREF(bound);
        }
        Py_DECREF(args);
    }
    PyObject *type, *value, *traceback;
    PyErr_Fetch(&type, &value, &traceback); /* draining must not see the exception */
    drain_log_queue(c);
    PyErr_Restore(type, value, traceback);
    return result;
}

/* Call a method whose result does not matter. */
static fmi2Status call_status(Component *c, const char *fmi_name, const char *method,
                              PyObject *args)
{
    PyGILState_STATE gil = enter_python();
    PyObject *result = call(c, method, args);
    fmi2Status status = result ? fmi2OK : exception_status(c, fmi_name);
    Py_XDECREF(result);
    PyGILState_Release(gil);
    return status;
}

static Component *component_of(fmi2Component handle)
{
    return (Component *)handle;
}

#define REQUIRE_COMPONENT(c)                                                                       \
    do {                                                                                           \
        if ((c) == NULL || (c)->instance == NULL)                                                  \
            return fmi2Error;                                                                      \
    } while (0)

#define REQUIRE_ARRAY(c, fmi_name, array, n)                                                       \
    do {                                                                                           \
        if ((n) > 0 && (array) == NULL) {                                                          \
            logf_component((c), fmi2Error, "%s: a NULL array for %zu values", (fmi_name),          \
                           (size_t)(n));                                                           \
            return fmi2Error;                                                                      \
        }                                                                                          \
    } while (0)

static PyObject *reference_list(const fmi2ValueReference vr[], size_t nvr)
{
    PyObject *list = PyList_New((Py_ssize_t)nvr);
    if (list == NULL)
        return NULL;
    for (size_t i = 0; i < nvr; ++i) {
        PyObject *item = PyLong_FromUnsignedLong(vr[i]);
        if (item == NULL) {
            Py_DECREF(list);
            return NULL;
        }
        PyList_SET_ITEM(list, (Py_ssize_t)i, item);
    }
    return list;
}

/* ------------------------------------------------------------------------- */
/* starting Python and creating the facade                                    */

static int ensure_interpreter(void)
{
    pthread_mutex_lock(&start_lock);
    if (!Py_IsInitialized()) {
        Py_InitializeEx(0);
        if (Py_IsInitialized())
            PyEval_SaveThread(); /* release the GIL; every call takes it (enter_python) */
    }
    int ok = Py_IsInitialized();
    pthread_mutex_unlock(&start_lock);
    return ok;
}

/* "file:///a%20b/resources/" -> "/a b/resources" (malloc'ed). */
static char *resource_path(const char *uri)
{
    const char *p = uri;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;
        if (strncmp(p, "localhost/", 10) == 0)
            p += 9;
    } else if (strncmp(p, "file:", 5) == 0) {
        p += 5;
    }
    size_t n = strlen(p);
    char *out = malloc(n + 1);
    if (out == NULL)
        return NULL;
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
        if (p[i] == '%' && i + 2 < n && isxdigit((unsigned char)p[i + 1]) &&
            isxdigit((unsigned char)p[i + 2])) {
            char hex[3] = {p[i + 1], p[i + 2], '\0'};
            out[k++] = (char)strtol(hex, NULL, 16);
            i += 2;
        } else {
            out[k++] = p[i];
        }
    }
    while (k > 1 && out[k - 1] == '/')
        --k;
    out[k] = '\0';
    return out;
}

/* Read "module\nClass\nguid\n" from resources/wire_fmu_facade.txt. */
static int read_facade_file(const char *resources, char module[MAX_LINE], char cls[MAX_LINE],
                            char guid[MAX_LINE])
{
    char path[MAX_LINE];
    if (snprintf(path, sizeof path, "%s/%s", resources, FACADE_FILE) >= (int)sizeof path)
        return 0;
    FILE *file = fopen(path, "r");
    if (file == NULL)
        return 0;
    char *lines[3] = {module, cls, guid};
    int ok = 1;
    for (int i = 0; i < 3 && ok; ++i) {
        ok = fgets(lines[i], MAX_LINE, file) != NULL;
        if (ok)
            lines[i][strcspn(lines[i], "\r\n")] = '\0';
    }
    fclose(file);
    return ok && module[0] && cls[0];
}

static int prepend_sys_path(const char *folder)
{
    PyObject *path = PySys_GetObject("path"); /* borrowed */
    PyObject *entry = PyUnicode_DecodeFSDefault(folder);
    if (path == NULL || entry == NULL || !PyList_Check(path)) {
        Py_XDECREF(entry);
        return 0;
    }
    int present = PySequence_Contains(path, entry);
    int ok = present == 1 || (present == 0 && PyList_Insert(path, 0, entry) == 0);
    Py_DECREF(entry);
    return ok;
}

/* The facade class named in the resources, a new reference or NULL (exception set). */
static PyObject *facade_class(const char *resources, const char *module_name,
                              const char *class_name)
{
    if (!prepend_sys_path(resources)) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_RuntimeError, "sys.path is not a list");
        return NULL;
    }
    PyObject *module = PyImport_ImportModule(module_name);
    if (module == NULL)
        return NULL;
    PyObject *cls = PyObject_GetAttrString(module, class_name);
    Py_DECREF(module);
    return cls;
}

static PyObject *new_facade(Component *c, PyObject *cls, int visible)
{
    PyObject *kwargs = Py_BuildValue("{s:s,s:s,s:O}", "instance_name", c->name, "resources",
                                     c->resources, "visible", visible ? Py_True : Py_False);
    PyObject *args = PyTuple_New(0);
    PyObject *instance = (kwargs && args) ? PyObject_Call(cls, args, kwargs) : NULL;
    Py_XDECREF(kwargs);
    Py_XDECREF(args);
    return instance;
}

static void free_component(Component *c)
{
    if (c == NULL)
        return;
    free(c->name);
    free(c->resources);
    free(c->guid);
    free(c);
}

static char *copy_text(const char *text)
{
    return strdup(text ? text : "");
}

static int create_facade(Component *c, const char *guid, int visible)
{
    char module[MAX_LINE], cls_name[MAX_LINE], built_guid[MAX_LINE];
    if (!read_facade_file(c->resources, module, cls_name, built_guid)) {
        logf_component(c, fmi2Fatal, "fmi2Instantiate: cannot read %s/%s: not a wire_fmu FMU, or "
                       "its resources are incomplete", c->resources, FACADE_FILE);
        return 0;
    }
    if (built_guid[0] && strcmp(built_guid, guid) != 0) {
        logf_component(c, fmi2Fatal, "fmi2Instantiate: GUID %s does not match this FMU's %s",
                       guid, built_guid);
        return 0;
    }
    PyGILState_STATE gil = enter_python();
    PyObject *cls = facade_class(c->resources, module, cls_name);
    PyObject *instance = cls ? new_facade(c, cls, visible) : NULL;
    Py_XDECREF(cls);
    if (instance == NULL) {
        PyObject *type, *value, *traceback;
        PyErr_Fetch(&type, &value, &traceback);
        PyErr_NormalizeException(&type, &value, &traceback);
        PyObject *text = value ? PyObject_Str(value) : NULL;
        const char *what = text ? PyUnicode_AsUTF8(text) : NULL;
        PyErr_Clear();
        logf_component(c, fmi2Fatal, "fmi2Instantiate: the facade %s.%s could not be created: "
                       "%s: %s", module, cls_name, type ? ((PyTypeObject *)type)->tp_name : "?",
                       what ? what : "");
        Py_XDECREF(text);
        Py_XDECREF(type);
        Py_XDECREF(value);
        Py_XDECREF(traceback);
        PyGILState_Release(gil);
        return 0;
    }
    c->instance = instance;
    drain_log_queue(c);
    PyGILState_Release(gil);
    return 1;
}

/* ------------------------------------------------------------------------- */
/* FMI 2.0: common functions                                                  */

const char *fmi2GetTypesPlatform(void)
{
    return fmi2TypesPlatform;
}

const char *fmi2GetVersion(void)
{
    return fmi2Version;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn)
{
    const char *name = instanceName ? instanceName : "";
    if (fmuType != fmi2CoSimulation || fmuResourceLocation == NULL || fmuGUID == NULL) {
        const char *why = fmuType != fmi2CoSimulation ? "only co-simulation is supported"
                          : fmuResourceLocation == NULL ? "no resource location was given"
                                                        : "no GUID was given";
        log_to_host(functions, name, 1, fmi2Error, NULL, why);
        return NULL;
    }
    Component *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    c->name = copy_text(name);
    c->resources = resource_path(fmuResourceLocation);
    c->guid = copy_text(fmuGUID);
    if (functions != NULL)
        c->callbacks = *functions;
    c->logging_on = loggingOn != fmi2False;
    if (c->name == NULL || c->resources == NULL || c->guid == NULL) {
        free_component(c);
        return NULL;
    }
    if (!ensure_interpreter()) {
        logf_component(c, fmi2Fatal, "fmi2Instantiate: the Python interpreter could not start");
        free_component(c);
        return NULL;
    }
    if (!create_facade(c, fmuGUID, visible != fmi2False)) {
        free_component(c);
        return NULL;
    }
    return c;
}

void fmi2FreeInstance(fmi2Component handle)
{
    Component *c = component_of(handle);
    if (c == NULL)
        return;
    if (c->instance != NULL || c->strings != NULL) {
        PyGILState_STATE gil = enter_python();
        Py_CLEAR(c->strings);
        Py_CLEAR(c->instance);
        PyGILState_Release(gil);
    }
    free_component(c);
}

fmi2Status fmi2SetDebugLogging(fmi2Component handle, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)nCategories;
    (void)categories;
    c->logging_on = loggingOn != fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component handle, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    PyGILState_STATE gil = enter_python();
    PyObject *stop = stopTimeDefined ? PyFloat_FromDouble(stopTime) : Py_NewRef(Py_None);
    PyObject *tol = toleranceDefined ? PyFloat_FromDouble(tolerance) : Py_NewRef(Py_None);
    PyObject *args = (stop && tol) ? Py_BuildValue("(dOO)", startTime, stop, tol) : NULL;
    Py_XDECREF(stop);
    Py_XDECREF(tol);
    PyGILState_Release(gil);
    return call_status(c, "fmi2SetupExperiment", "setup_experiment", args);
}

/* The facade's <method>() for an FMI call without arguments. */
static fmi2Status call_no_arguments(fmi2Component handle, const char *fmi_name,
                                    const char *method)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    PyGILState_STATE gil = enter_python();
    PyObject *args = PyTuple_New(0);
    PyGILState_Release(gil);
    return call_status(c, fmi_name, method, args);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component handle)
{
    return call_no_arguments(handle, "fmi2EnterInitializationMode", "enter_initialization_mode");
}

fmi2Status fmi2ExitInitializationMode(fmi2Component handle)
{
    return call_no_arguments(handle, "fmi2ExitInitializationMode", "exit_initialization_mode");
}

fmi2Status fmi2Terminate(fmi2Component handle)
{
    return call_no_arguments(handle, "fmi2Terminate", "terminate");
}

fmi2Status fmi2Reset(fmi2Component handle)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    PyGILState_STATE gil = enter_python();
    PyObject *cls = Py_NewRef((PyObject *)Py_TYPE(c->instance));
    PyObject *fresh = new_facade(c, cls, 0);
    Py_DECREF(cls);
    fmi2Status status = fmi2OK;
    if (fresh == NULL) {
        c->reported = 0;
        status = exception_status(c, "fmi2Reset");
    } else {
        Py_SETREF(c->instance, fresh);
        drain_log_queue(c);
    }
    PyGILState_Release(gil);
    return status;
}

/* ------------------------------------------------------------------------- */
/* getting and setting values                                                 */

typedef int (*Convert)(PyObject *item, void *values, size_t i, Component *c);

static int to_real(PyObject *item, void *values, size_t i, Component *c)
{
    (void)c;
    double v = PyFloat_AsDouble(item);
    ((fmi2Real *)values)[i] = v;
    return !(v == -1.0 && PyErr_Occurred());
}

static int to_integer(PyObject *item, void *values, size_t i, Component *c)
{
    (void)c;
    long v = PyLong_AsLong(item);
    if (v == -1 && PyErr_Occurred())
        return 0;
    if (v < INT32_MIN || v > INT32_MAX) {
        PyErr_SetString(PyExc_OverflowError, "value outside the range of fmi2Integer");
        return 0;
    }
    ((fmi2Integer *)values)[i] = (fmi2Integer)v;
    return 1;
}

static int to_boolean(PyObject *item, void *values, size_t i, Component *c)
{
    (void)c;
    int v = PyObject_IsTrue(item);
    ((fmi2Boolean *)values)[i] = v > 0 ? fmi2True : fmi2False;
    return v >= 0;
}

static int to_string(PyObject *item, void *values, size_t i, Component *c)
{
    PyObject *bytes = PyUnicode_AsUTF8String(item);
    if (bytes == NULL || PyList_Append(c->strings, bytes) != 0) {
        Py_XDECREF(bytes);
        return 0;
    }
    ((fmi2String *)values)[i] = PyBytes_AS_STRING(bytes);
    Py_DECREF(bytes); /* c->strings holds it until the next fmi2GetString */
    return 1;
}

static fmi2Status get_values(Component *c, const char *fmi_name, const char *method,
                             const fmi2ValueReference vr[], size_t nvr, void *values,
                             Convert convert)
{
    if (nvr == 0)
        return fmi2OK;
    PyGILState_STATE gil = enter_python();
    if (convert == to_string) {
        Py_CLEAR(c->strings);
        c->strings = PyList_New(0);
        if (c->strings == NULL) {
            PyErr_Clear();
            PyGILState_Release(gil);
            logf_component(c, fmi2Error, "%s: out of memory", fmi_name);
            return fmi2Error;
        }
    }
    PyObject *refs = reference_list(vr, nvr);
    PyObject *result = call(c, method, refs ? PyTuple_Pack(1, refs) : NULL);
    Py_XDECREF(refs);
    fmi2Status status = fmi2OK;
    if (result == NULL) {
        status = exception_status(c, fmi_name);
    } else if (!PyList_Check(result) || PyList_GET_SIZE(result) != (Py_ssize_t)nvr) {
        logf_component(c, fmi2Error, "%s: the facade returned %s values for %zu references",
                       fmi_name, PyList_Check(result) ? "a different number of" : "no list of",
                       nvr);
        status = fmi2Error;
    } else {
        for (size_t i = 0; i < nvr && status == fmi2OK; ++i) {
            if (!convert(PyList_GET_ITEM(result, (Py_ssize_t)i), values, i, c))
                status = exception_status(c, fmi_name);
        }
    }
    Py_XDECREF(result);
    PyGILState_Release(gil);
    return status;
}

static fmi2Status set_values(Component *c, const char *fmi_name, const char *method,
                             const fmi2ValueReference vr[], size_t nvr, PyObject *values)
{
    PyObject *refs = reference_list(vr, nvr);
    PyObject *args = (refs && values) ? PyTuple_Pack(2, refs, values) : NULL;
    Py_XDECREF(refs);
    Py_XDECREF(values);
    PyObject *result = call(c, method, args);
    fmi2Status status = result ? fmi2OK : exception_status(c, fmi_name);
    Py_XDECREF(result);
    return status;
}

static fmi2Status get_all(fmi2Component handle, const char *fmi_name, const char *method,
                          const fmi2ValueReference vr[], size_t nvr, void *value, Convert convert)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    REQUIRE_ARRAY(c, fmi_name, vr, nvr);
    REQUIRE_ARRAY(c, fmi_name, value, nvr);
    return get_values(c, fmi_name, method, vr, nvr, value, convert);
}

fmi2Status fmi2GetReal(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[])
{
    return get_all(handle, "fmi2GetReal", "get_real", vr, nvr, value, to_real);
}

fmi2Status fmi2GetInteger(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[])
{
    return get_all(handle, "fmi2GetInteger", "get_integer", vr, nvr, value, to_integer);
}

fmi2Status fmi2GetBoolean(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[])
{
    return get_all(handle, "fmi2GetBoolean", "get_boolean", vr, nvr, value, to_boolean);
}

fmi2Status fmi2GetString(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[])
{
    return get_all(handle, "fmi2GetString", "get_string", vr, nvr, (void *)value, to_string);
}

typedef PyObject *(*ToPython)(const void *values, size_t i);

static PyObject *from_real(const void *values, size_t i)
{
    return PyFloat_FromDouble(((const fmi2Real *)values)[i]);
}

static PyObject *from_integer(const void *values, size_t i)
{
    return PyLong_FromLong(((const fmi2Integer *)values)[i]);
}

static PyObject *from_boolean(const void *values, size_t i)
{
    return PyBool_FromLong(((const fmi2Boolean *)values)[i] != fmi2False);
}

static PyObject *from_string(const void *values, size_t i)
{
    const char *text = ((const fmi2String *)values)[i];
    text = text ? text : "";
    return PyUnicode_DecodeUTF8(text, (Py_ssize_t)strlen(text), "replace");
}

/* The facade's set_<type>(references, values) with the host's values as a list. */
static fmi2Status set_all(fmi2Component handle, const char *fmi_name, const char *method,
                          const fmi2ValueReference vr[], size_t nvr, const void *value,
                          ToPython convert)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    REQUIRE_ARRAY(c, fmi_name, vr, nvr);
    REQUIRE_ARRAY(c, fmi_name, value, nvr);
    PyGILState_STATE gil = enter_python();
    PyObject *values = PyList_New((Py_ssize_t)nvr);
    for (size_t i = 0; values && i < nvr; ++i) {
        PyObject *item = convert(value, i);
        if (item == NULL)
            Py_CLEAR(values);
        else
            PyList_SET_ITEM(values, (Py_ssize_t)i, item);
    }
    fmi2Status status = set_values(c, fmi_name, method, vr, nvr, values);
    PyGILState_Release(gil);
    return status;
}

fmi2Status fmi2SetReal(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[])
{
    return set_all(handle, "fmi2SetReal", "set_real", vr, nvr, value, from_real);
}

fmi2Status fmi2SetInteger(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[])
{
    return set_all(handle, "fmi2SetInteger", "set_integer", vr, nvr, value, from_integer);
}

fmi2Status fmi2SetBoolean(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[])
{
    return set_all(handle, "fmi2SetBoolean", "set_boolean", vr, nvr, value, from_boolean);
}

fmi2Status fmi2SetString(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[])
{
    return set_all(handle, "fmi2SetString", "set_string", vr, nvr, value, from_string);
}

/* ------------------------------------------------------------------------- */
/* FMU states                                                                 */

fmi2Status fmi2GetFMUstate(fmi2Component handle, fmi2FMUstate *FMUstate)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    REQUIRE_ARRAY(c, "fmi2GetFMUstate", FMUstate, 1);
    PyGILState_STATE gil = enter_python();
    PyObject *state = call(c, "_get_fmu_state", PyTuple_New(0));
    fmi2Status status = fmi2OK;
    if (state == NULL) {
        status = exception_status(c, "fmi2GetFMUstate");
    } else {
        Py_XDECREF((PyObject *)*FMUstate); /* FMI 2.0: a given state is overwritten */
        *FMUstate = state;
    }
    PyGILState_Release(gil);
    return status;
}

fmi2Status fmi2SetFMUstate(fmi2Component handle, fmi2FMUstate FMUstate)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    REQUIRE_ARRAY(c, "fmi2SetFMUstate", FMUstate, 1);
    PyGILState_STATE gil = enter_python();
    PyObject *args = PyTuple_Pack(1, (PyObject *)FMUstate);
    PyGILState_Release(gil);
    fmi2Status status = call_status(c, "fmi2SetFMUstate", "_set_fmu_state", args);
    if (status == fmi2OK)
        c->refused = 0;
    return status;
}

fmi2Status fmi2FreeFMUstate(fmi2Component handle, fmi2FMUstate *FMUstate)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    if (FMUstate == NULL || *FMUstate == NULL)
        return fmi2OK;
    PyGILState_STATE gil = enter_python();
    Py_DECREF((PyObject *)*FMUstate);
    *FMUstate = NULL;
    PyGILState_Release(gil);
    return fmi2OK;
}

/* The serialised state as bytes (a new reference) or NULL with the status logged. */
static PyObject *state_bytes(Component *c, const char *fmi_name, fmi2FMUstate state)
{
    PyObject *args = PyTuple_Pack(1, (PyObject *)state);
    PyObject *bytes = call(c, "_fmu_state_to_bytes", args);
    if (bytes == NULL) {
        exception_status(c, fmi_name);
        return NULL;
    }
    if (!PyBytes_Check(bytes)) {
        logf_component(c, fmi2Error, "%s: the facade serialised a state to %s, not bytes",
                       fmi_name, Py_TYPE(bytes)->tp_name);
        Py_DECREF(bytes);
        return NULL;
    }
    return bytes;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component handle, fmi2FMUstate FMUstate, size_t *size)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    REQUIRE_ARRAY(c, "fmi2SerializedFMUstateSize", FMUstate, 1);
    REQUIRE_ARRAY(c, "fmi2SerializedFMUstateSize", size, 1);
    PyGILState_STATE gil = enter_python();
    PyObject *bytes = state_bytes(c, "fmi2SerializedFMUstateSize", FMUstate);
    if (bytes != NULL)
        *size = (size_t)PyBytes_GET_SIZE(bytes);
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return bytes ? fmi2OK : fmi2Error;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component handle, fmi2FMUstate FMUstate,
                                 fmi2Byte serializedState[], size_t size)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    REQUIRE_ARRAY(c, "fmi2SerializeFMUstate", FMUstate, 1);
    REQUIRE_ARRAY(c, "fmi2SerializeFMUstate", serializedState, size);
    PyGILState_STATE gil = enter_python();
    PyObject *bytes = state_bytes(c, "fmi2SerializeFMUstate", FMUstate);
    fmi2Status status = bytes ? fmi2OK : fmi2Error;
    if (bytes != NULL && (size_t)PyBytes_GET_SIZE(bytes) != size) {
        logf_component(c, fmi2Error, "fmi2SerializeFMUstate: the buffer holds %zu bytes, the "
                       "state needs %zd", size, PyBytes_GET_SIZE(bytes));
        status = fmi2Error;
    } else if (bytes != NULL) {
        memcpy(serializedState, PyBytes_AS_STRING(bytes), size);
    }
    Py_XDECREF(bytes);
    PyGILState_Release(gil);
    return status;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component handle, const fmi2Byte serializedState[],
                                   size_t size, fmi2FMUstate *FMUstate)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    REQUIRE_ARRAY(c, "fmi2DeSerializeFMUstate", serializedState, size);
    REQUIRE_ARRAY(c, "fmi2DeSerializeFMUstate", FMUstate, 1);
    PyGILState_STATE gil = enter_python();
    PyObject *bytes = PyBytes_FromStringAndSize(serializedState, (Py_ssize_t)size);
    PyObject *state = call(c, "_fmu_state_from_bytes", bytes ? PyTuple_Pack(1, bytes) : NULL);
    Py_XDECREF(bytes);
    fmi2Status status = fmi2OK;
    if (state == NULL) {
        status = exception_status(c, "fmi2DeSerializeFMUstate");
    } else {
        Py_XDECREF((PyObject *)*FMUstate);
        *FMUstate = state;
    }
    PyGILState_Release(gil);
    return status;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component handle, const fmi2ValueReference vUnknown[],
                                        size_t nUnknown, const fmi2ValueReference vKnown[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)vUnknown, (void)nUnknown, (void)vKnown, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    logf_component(c, fmi2Error, "fmi2GetDirectionalDerivative: not provided "
                   "(providesDirectionalDerivative is false)");
    return fmi2Error;
}

/* ------------------------------------------------------------------------- */
/* FMI 2.0: co-simulation                                                     */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component handle, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[])
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)vr, (void)nvr, (void)order, (void)value;
    logf_component(c, fmi2Error, "fmi2SetRealInputDerivatives: not provided "
                   "(canInterpolateInputs is false)");
    return fmi2Error;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component handle, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[], fmi2Real value[])
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)vr, (void)nvr, (void)order, (void)value;
    logf_component(c, fmi2Error, "fmi2GetRealOutputDerivatives: not provided "
                   "(maxOutputDerivativeOrder is 0)");
    return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component handle, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)noSetFMUStatePriorToCurrentPoint;
    PyGILState_STATE gil = enter_python();
    PyObject *args = Py_BuildValue("(dd)", currentCommunicationPoint, communicationStepSize);
    PyObject *result = call(c, "do_step", args);
    fmi2Status status;
    if (result == NULL) {
        status = exception_status(c, "fmi2DoStep");
    } else {
        int taken = PyObject_IsTrue(result);
        status = taken > 0 ? fmi2OK : taken == 0 ? fmi2Discard : exception_status(c, "fmi2DoStep");
    }
    if (status == fmi2OK || status == fmi2Discard) {
        /* a refused step leaves the unit where it was: at the step's start */
        c->refused = status == fmi2Discard;
        c->last_time = currentCommunicationPoint + (c->refused ? 0.0 : communicationStepSize);
    }
    Py_XDECREF(result);
    PyGILState_Release(gil);
    return status;
}

fmi2Status fmi2CancelStep(fmi2Component handle)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    logf_component(c, fmi2Error, "fmi2CancelStep: steps are never asynchronous here");
    return fmi2Error;
}

static fmi2Status no_status(Component *c, const char *fmi_name)
{
    logf_component(c, fmi2Discard, "%s: no such status (steps are never asynchronous)", fmi_name);
    return fmi2Discard;
}

fmi2Status fmi2GetStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Status *value)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)s, (void)value;
    return no_status(c, "fmi2GetStatus");
}

fmi2Status fmi2GetRealStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Real *value)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    if (s == fmi2LastSuccessfulTime && value != NULL) {
        *value = c->last_time;
        return fmi2OK;
    }
    return no_status(c, "fmi2GetRealStatus");
}

fmi2Status fmi2GetIntegerStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Integer *value)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)s, (void)value;
    return no_status(c, "fmi2GetIntegerStatus");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Boolean *value)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    if (s == fmi2Terminated && value != NULL) {
        /* after a refused step a master that cannot roll back and retry shorter must stop */
        *value = c->refused ? fmi2True : fmi2False;
        return fmi2OK;
    }
    return no_status(c, "fmi2GetBooleanStatus");
}

fmi2Status fmi2GetStringStatus(fmi2Component handle, const fmi2StatusKind s, fmi2String *value)
{
    Component *c = component_of(handle);
    REQUIRE_COMPONENT(c);
    (void)s, (void)value;
    return no_status(c, "fmi2GetStringStatus");
}
