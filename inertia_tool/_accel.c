/*
 * inertia_tool._accel -- optional C kernels for the engine's hot loops.
 *
 * Written against the CPython C API and the buffer protocol only (no numpy headers), so it builds with a
 * C compiler and the Python headers.  Every function here has a pure-numpy twin that stays the reference
 * (inertia_tool/weld.py, checks.py, volume.py); the Python modules call these only when this module
 * imports and INERTIA_TOOL_NO_ACCEL is not set.  Results are identical to the numpy path (welding, edge
 * census, shell labels) or equal to round-off (the compensated integration sums).
 *
 * Sections:
 *   1. buffers     -- format / shape checks shared by the kernels
 *   2. Welder      -- streaming exact weld of float32 or float64 points (weld.py)
 *   3. edge_census -- boundary / non-manifold / misoriented edges (checks.edge_topology)
 *   4. shell_labels-- union-find connected components of faces (checks.shell_labels)
 *   5. tetra_sums  -- signed-tetrahedron volume integrals with compensated sums (volume._tetra_sums)
 *
 * Safety: every index read from an array is bounds-checked before use, sizes are checked against
 * overflow before allocation, NaN coordinates are hashed by their bit pattern (never compared as floats),
 * and the GIL is released around every loop over faces or points (buffers stay pinned by their views).
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ======================================================================================================
 * 1. buffers
 * ====================================================================================================== */

static int
host_is_little(void)
{
    const uint16_t one = 1;
    return *(const uint8_t *)&one == 1;
}

/* The element code of a struct-module format ("f", "<f", "=d", "l", ...) if the data is in native byte
 * order, else 0. */
static char
native_code(const char *fmt)
{
    if (fmt == NULL) {
        return 'B';
    }
    if (fmt[0] == '@' || fmt[0] == '=') {
        fmt++;
    }
    else if (fmt[0] == '<') {
        if (!host_is_little()) {
            return 0;
        }
        fmt++;
    }
    else if (fmt[0] == '>' || fmt[0] == '!') {
        if (host_is_little()) {
            return 0;
        }
        fmt++;
    }
    if (fmt[0] == 0 || fmt[1] != 0) {
        return 0;
    }
    return fmt[0];
}

/* Signed integers of 4 or 8 bytes (numpy int32 / int64); returns the item size or 0. */
static int
signed_int_size(const Py_buffer *view)
{
    char c = native_code(view->format);
    if (c != 'i' && c != 'l' && c != 'q' && c != 'n') {
        return 0;
    }
    if (view->itemsize != 4 && view->itemsize != 8) {
        return 0;
    }
    return (int)view->itemsize;
}

static inline int64_t
index_at(const void *base, int size, size_t i)
{
    return size == 8 ? ((const int64_t *)base)[i] : (int64_t)((const int32_t *)base)[i];
}

/* A C-contiguous (m, 3) array of signed 4- or 8-byte integers: the faces.  Fills *m, *size. */
static int
get_faces(PyObject *obj, Py_buffer *view, Py_ssize_t *m, int *size)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        return -1;
    }
    *size = signed_int_size(view);
    if (*size == 0 || view->ndim != 2 || view->shape[1] != 3) {
        PyErr_Format(PyExc_ValueError, "Expected `faces` as a C-contiguous (m, 3) int32 or int64 array, "
                     "got format %s with %d dimensions", view->format ? view->format : "B", view->ndim);
        PyBuffer_Release(view);
        return -1;
    }
    *m = view->shape[0];
    return 0;
}

/* Refuse a vertex count the int32 index space cannot hold. */
static int
check_vertex_count(Py_ssize_t n)
{
    if (n < 0 || n > (Py_ssize_t)INT32_MAX - 1) {
        PyErr_Format(PyExc_ValueError, "Expected 0 <= n_vertices < 2**31 - 1, got %zd", n);
        return -1;
    }
    return 0;
}

/* First face index outside [0, n), or -1 when all are in range (GIL may be released). */
static Py_ssize_t
first_bad_index(const void *faces, int size, size_t count, int64_t n)
{
    for (size_t i = 0; i < count; i++) {
        int64_t v = index_at(faces, size, i);
        if (v < 0 || v >= n) {
            return (Py_ssize_t)i;
        }
    }
    return -1;
}

static int
check_indices(const void *faces, int size, size_t count, int64_t n)
{
    Py_ssize_t bad;
    Py_BEGIN_ALLOW_THREADS
    bad = first_bad_index(faces, size, count, n);
    Py_END_ALLOW_THREADS
    if (bad >= 0) {
        PyErr_Format(PyExc_ValueError, "Expected face indices in 0..%lld, got %lld at position %zd",
                     (long long)n - 1, (long long)index_at(faces, size, (size_t)bad), bad);
        return -1;
    }
    return 0;
}

/* ======================================================================================================
 * 2. Welder: streaming exact weld
 *
 * An open-addressing hash table (linear probing, load factor <= 1/2, doubled when full) maps the exact
 * bit pattern of a point -- three float32 or three float64 words, -0.0 folded onto +0.0 -- to a vertex id
 * assigned in order of first appearance.  The table stores only ids; the keys (the full 12 or 24 bytes)
 * live in an array indexed by id and every probe compares the full key, so two different points can
 * never share a vertex whatever the hash does.
 * ====================================================================================================== */

#define MAX_VERTICES ((size_t)INT32_MAX - 1)

enum { WELD_OK = 0, WELD_NOMEM = 1, WELD_TOO_MANY = 2 };

typedef struct {
    PyObject_HEAD
    int wide;              /* 0: float32 keys (3 x 32 bits); 1: float64 keys (3 x 64 bits) */
    int busy;              /* a feed is running with the GIL released */
    uint32_t *slots;       /* vertex id + 1, 0 = empty; mask + 1 entries */
    size_t mask;
    unsigned char *keys;   /* keys_cap keys of key_bytes each, in vertex-id order */
    size_t keys_cap;
    size_t count;          /* vertices so far */
    uint64_t points;       /* points fed so far */
} WelderObject;

static inline size_t
key_bytes(const WelderObject *w)
{
    return w->wide ? 24 : 12;
}

static inline uint64_t
fmix64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    h ^= h >> 33;
    return h;
}

static inline uint64_t
hash32(const uint32_t *k)
{
    uint64_t h = (((uint64_t)k[1] << 32) | k[0]) * 0x9E3779B97F4A7C15ULL;
    h ^= (uint64_t)k[2] * 0xC2B2AE3D27D4EB4FULL;
    return fmix64(h);
}

static inline uint64_t
hash64(const uint64_t *k)
{
    uint64_t h = k[0] * 0x9E3779B97F4A7C15ULL;
    h ^= h >> 29;
    h += k[1] * 0xC2B2AE3D27D4EB4FULL;
    h ^= h >> 31;
    h += k[2] * 0x165667B19E3779F9ULL;
    return fmix64(h);
}

/* Hash of the stored key of vertex `id`. */
static inline uint64_t
hash_stored(const WelderObject *w, size_t id)
{
    return w->wide ? hash64((const uint64_t *)w->keys + 3 * id) : hash32((const uint32_t *)w->keys + 3 * id);
}

/* Rebuild the table at twice the size from the key array. */
static int
welder_grow_table(WelderObject *w)
{
    size_t capacity = w->mask + 1;
    if (capacity > SIZE_MAX / 2 / sizeof(uint32_t)) {
        return WELD_NOMEM;
    }
    size_t new_capacity = 2 * capacity;
    uint32_t *slots = (uint32_t *)calloc(new_capacity, sizeof(uint32_t));
    if (slots == NULL) {
        return WELD_NOMEM;
    }
    size_t mask = new_capacity - 1;
    for (size_t id = 0; id < w->count; id++) {
        size_t i = (size_t)hash_stored(w, id) & mask;
        for (size_t probe = 0; probe <= mask && slots[i] != 0; probe++) {
            i = (i + 1) & mask;
        }
        slots[i] = (uint32_t)(id + 1);
    }
    free(w->slots);
    w->slots = slots;
    w->mask = mask;
    return WELD_OK;
}

static int
welder_grow_keys(WelderObject *w)
{
    size_t cap = w->keys_cap ? 2 * w->keys_cap : 1024, kb = key_bytes(w);
    if (cap > MAX_VERTICES + 1) {
        cap = MAX_VERTICES + 1;
    }
    if (cap > SIZE_MAX / kb) {
        return WELD_NOMEM;
    }
    unsigned char *keys = (unsigned char *)realloc(w->keys, cap * kb);
    if (keys == NULL) {
        return WELD_NOMEM;
    }
    w->keys = keys;
    w->keys_cap = cap;
    return WELD_OK;
}

/* The id of `key` (three KEY_T words), inserting it if new.  Returns a WELD_* status. */
#define DEFINE_LOOKUP(NAME, KEY_T, HASH)                                                                  \
static inline int                                                                                         \
NAME(WelderObject *w, const KEY_T *key, int32_t *id_out)                                                  \
{                                                                                                         \
    const KEY_T *keys = (const KEY_T *)w->keys;                                                           \
    size_t i = (size_t)HASH(key) & w->mask;                                                               \
    for (size_t probe = 0; probe <= w->mask; probe++) {                                                   \
        uint32_t s = w->slots[i];                                                                         \
        if (s == 0) {                                                                                     \
            break;                                                                                        \
        }                                                                                                 \
        const KEY_T *o = keys + 3 * (size_t)(s - 1);                                                      \
        if (o[0] == key[0] && o[1] == key[1] && o[2] == key[2]) {                                         \
            *id_out = (int32_t)(s - 1);                                                                   \
            return WELD_OK;                                                                               \
        }                                                                                                 \
        i = (i + 1) & w->mask;                                                                            \
    }                                                                                                     \
    if (w->count >= MAX_VERTICES) {                                                                       \
        return WELD_TOO_MANY;                                                                             \
    }                                                                                                     \
    if (w->count == w->keys_cap) {                                                                        \
        int st = welder_grow_keys(w);                                                                     \
        if (st != WELD_OK) {                                                                              \
            return st;                                                                                    \
        }                                                                                                 \
    }                                                                                                     \
    if (2 * (w->count + 1) > w->mask + 1) {                                                               \
        int st = welder_grow_table(w);                                                                    \
        if (st != WELD_OK) {                                                                              \
            return st;                                                                                    \
        }                                                                                                 \
        i = (size_t)HASH(key) & w->mask;                                                                  \
        for (size_t probe = 0; probe <= w->mask && w->slots[i] != 0; probe++) {                           \
            i = (i + 1) & w->mask;                                                                        \
        }                                                                                                 \
    }                                                                                                     \
    memcpy((KEY_T *)w->keys + 3 * w->count, key, 3 * sizeof(KEY_T));                                     \
    w->slots[i] = (uint32_t)(w->count + 1);                                                               \
    *id_out = (int32_t)w->count;                                                                          \
    w->count++;                                                                                           \
    return WELD_OK;                                                                                       \
}

DEFINE_LOOKUP(lookup32, uint32_t, hash32)
DEFINE_LOOKUP(lookup64, uint64_t, hash64)

static int
Welder_init(WelderObject *w, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {"dtype", "expected_vertices", NULL};
    const char *dtype = NULL;
    Py_ssize_t expected = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "s|n", kwlist, &dtype, &expected)) {
        return -1;
    }
    if (w->slots != NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Welder is already initialised");
        return -1;
    }
    if (strcmp(dtype, "float32") == 0) {
        w->wide = 0;
    }
    else if (strcmp(dtype, "float64") == 0) {
        w->wide = 1;
    }
    else {
        PyErr_Format(PyExc_ValueError, "Expected dtype 'float32' or 'float64', got '%s'", dtype);
        return -1;
    }
    if (expected < 0) {
        expected = 0;
    }
    if ((size_t)expected > MAX_VERTICES) {
        expected = (Py_ssize_t)MAX_VERTICES;
    }
    size_t capacity = 1024;
    while (capacity < 2 * (size_t)expected + 2) {
        capacity *= 2;
    }
    w->slots = (uint32_t *)calloc(capacity, sizeof(uint32_t));
    if (w->slots == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    w->mask = capacity - 1;
    w->count = 0;
    w->points = 0;
    w->busy = 0;
    return 0;
}

static void
Welder_dealloc(WelderObject *w)
{
    free(w->slots);
    free(w->keys);
    Py_TYPE(w)->tp_free((PyObject *)w);
}

static int
welder_ready(WelderObject *w)
{
    if (w->slots == NULL) {
        PyErr_SetString(PyExc_RuntimeError, "Welder was not initialised");
        return -1;
    }
    if (w->busy) {
        PyErr_SetString(PyExc_RuntimeError, "Welder is in use by another thread");
        return -1;
    }
    return 0;
}

/* Welder.feed(points, out): weld (k, 3) or (k, j, 3) points (any strides, the welder's float type) and
 * write each point's vertex id, in C order, into the contiguous int32 buffer `out` of k[*j] entries. */
static PyObject *
Welder_feed(WelderObject *w, PyObject *args)
{
    PyObject *points_obj, *out_obj;
    if (!PyArg_ParseTuple(args, "OO", &points_obj, &out_obj) || welder_ready(w) < 0) {
        return NULL;
    }
    Py_buffer pts, out;
    if (PyObject_GetBuffer(points_obj, &pts, PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (PyObject_GetBuffer(out_obj, &out, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyBuffer_Release(&pts);
        return NULL;
    }
    char code = native_code(pts.format);
    int ok_type = w->wide ? (code == 'd' && pts.itemsize == 8) : (code == 'f' && pts.itemsize == 4);
    if (!ok_type || (pts.ndim != 2 && pts.ndim != 3) || pts.shape[pts.ndim - 1] != 3) {
        PyErr_Format(PyExc_ValueError, "Expected points as a (k, 3) or (k, j, 3) %s array, got format %s with "
                     "%d dimensions", w->wide ? "float64" : "float32", pts.format ? pts.format : "B", pts.ndim);
        goto fail;
    }
    Py_ssize_t n0 = pts.shape[0], n1 = pts.ndim == 3 ? pts.shape[1] : 1;
    Py_ssize_t s0 = pts.strides[0], s1 = pts.ndim == 3 ? pts.strides[1] : 0, sc = pts.strides[pts.ndim - 1];
    if (n1 != 0 && n0 > PY_SSIZE_T_MAX / n1) {
        PyErr_SetString(PyExc_OverflowError, "too many points");
        goto fail;
    }
    Py_ssize_t total = n0 * n1;
    if (signed_int_size(&out) != 4 || out.ndim != 1 || out.shape[0] != total) {
        PyErr_Format(PyExc_ValueError, "Expected `out` as a contiguous int32 array of %zd entries", total);
        goto fail;
    }
    int status = WELD_OK;
    int32_t *ids = (int32_t *)out.buf;
    const char *base = (const char *)pts.buf;
    w->busy = 1;
    Py_BEGIN_ALLOW_THREADS
    Py_ssize_t k = 0;
    for (Py_ssize_t i0 = 0; i0 < n0 && status == WELD_OK; i0++) {
        for (Py_ssize_t i1 = 0; i1 < n1; i1++, k++) {
            const char *p = base + i0 * s0 + i1 * s1;
            if (w->wide) {
                uint64_t key[3];
                for (int c = 0; c < 3; c++) {
                    memcpy(&key[c], p + c * sc, 8);
                    if (key[c] == 0x8000000000000000ULL) {
                        key[c] = 0;   /* -0.0 -> +0.0 */
                    }
                }
                status = lookup64(w, key, &ids[k]);
            }
            else {
                uint32_t key[3];
                for (int c = 0; c < 3; c++) {
                    memcpy(&key[c], p + c * sc, 4);
                    if (key[c] == 0x80000000U) {
                        key[c] = 0;
                    }
                }
                status = lookup32(w, key, &ids[k]);
            }
            if (status != WELD_OK) {
                break;
            }
        }
    }
    Py_END_ALLOW_THREADS
    w->busy = 0;
    if (status == WELD_NOMEM) {
        PyErr_NoMemory();
        goto fail;
    }
    if (status == WELD_TOO_MANY) {
        PyErr_SetString(PyExc_OverflowError, "more than 2**31 - 2 distinct vertices");
        goto fail;
    }
    w->points += (uint64_t)total;
    PyBuffer_Release(&pts);
    PyBuffer_Release(&out);
    Py_RETURN_NONE;
fail:
    PyBuffer_Release(&pts);
    PyBuffer_Release(&out);
    return NULL;
}

/* Welder.vertices_into(out): the distinct points as float64, (count, 3) contiguous, in id order. */
static PyObject *
Welder_vertices_into(WelderObject *w, PyObject *out_obj)
{
    if (welder_ready(w) < 0) {
        return NULL;
    }
    Py_buffer out;
    if (PyObject_GetBuffer(out_obj, &out, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        return NULL;
    }
    if (native_code(out.format) != 'd' || out.itemsize != 8 || out.len != (Py_ssize_t)(w->count * 3 * 8)) {
        PyErr_Format(PyExc_ValueError, "Expected `out` as a contiguous float64 array of shape (%zu, 3)", w->count);
        PyBuffer_Release(&out);
        return NULL;
    }
    double *v = (double *)out.buf;
    Py_BEGIN_ALLOW_THREADS
    if (w->wide && w->count > 0) {      /* no memcpy of 0 bytes: keys (and out) may be NULL then */
        memcpy(v, w->keys, w->count * 24);
    }
    else {
        const float *f = (const float *)w->keys;
        for (size_t i = 0; i < 3 * w->count; i++) {
            v[i] = (double)f[i];
        }
    }
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&out);
    Py_RETURN_NONE;
}

static PyObject *
Welder_get_count(WelderObject *w, void *closure)
{
    return PyLong_FromSize_t(w->count);
}

static PyObject *
Welder_get_points(WelderObject *w, void *closure)
{
    return PyLong_FromUnsignedLongLong(w->points);
}

static PyMethodDef Welder_methods[] = {
    {"feed", (PyCFunction)Welder_feed, METH_VARARGS,
     "feed(points, out)\n\nWeld (k, 3) or (k, j, 3) points of the welder's dtype (any strides; -0.0 equals "
     "+0.0) and write their vertex ids (first-appearance order) into the contiguous int32 array `out`."},
    {"vertices_into", (PyCFunction)Welder_vertices_into, METH_O,
     "vertices_into(out)\n\nWrite the distinct points, (count, 3) float64, into `out`."},
    {NULL, NULL, 0, NULL}
};

static PyGetSetDef Welder_getset[] = {
    {"count", (getter)Welder_get_count, NULL, "Distinct points so far.", NULL},
    {"points", (getter)Welder_get_points, NULL, "Points fed so far.", NULL},
    {NULL, NULL, NULL, NULL, NULL}
};

static PyTypeObject WelderType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "inertia_tool._accel.Welder",
    .tp_doc = "Welder(dtype, expected_vertices=0)\n\nStreaming exact weld: a hash table on the exact bit "
              "pattern of (x, y, z) ('float32' or 'float64'), persisting across feed() calls.",
    .tp_basicsize = sizeof(WelderObject),
    .tp_itemsize = 0,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Welder_init,
    .tp_dealloc = (destructor)Welder_dealloc,
    .tp_methods = Welder_methods,
    .tp_getset = Welder_getset,
};

/* ======================================================================================================
 * 3. edge_census
 *
 * Directed edges a->b (three per face) are bucketed by their start vertex a (a CSR adjacency, 3m int32
 * targets plus n+1 offsets) and each bucket is sorted.  An undirected edge {a, b} is used fwd times as a->b
 * (the run of b in a's bucket) and bwd times as b->a (found by binary search in b's bucket); it is counted
 * once, from its smaller end or from the only end that uses it.  Definitions as checks.edge_topology:
 * boundary = used once, non-manifold = more than twice, misoriented = twice in the same direction.
 * ====================================================================================================== */

#define SAMPLE 5

typedef struct {
    uint64_t key[SAMPLE];   /* u * n + v, u < v: the numpy path's sort key of the undirected edge */
    int count;
} SmallestKeys;

static void
keep_smallest(SmallestKeys *s, uint64_t key)
{
    if (s->count == SAMPLE && key >= s->key[SAMPLE - 1]) {
        return;
    }
    int i = s->count < SAMPLE ? s->count++ : SAMPLE - 1;
    while (i > 0 && s->key[i - 1] > key) {
        s->key[i] = s->key[i - 1];
        i--;
    }
    s->key[i] = key;
}

static int
cmp_int32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static void
sort_bucket(int32_t *t, size_t len)
{
    if (len > 32) {
        qsort(t, len, sizeof(int32_t), cmp_int32);
        return;
    }
    for (size_t i = 1; i < len; i++) {
        int32_t x = t[i];
        size_t j = i;
        while (j > 0 && t[j - 1] > x) {
            t[j] = t[j - 1];
            j--;
        }
        t[j] = x;
    }
}

/* Occurrences of x in the sorted t[0:len]. */
static size_t
count_sorted(const int32_t *t, size_t len, int32_t x)
{
    size_t lo = 0, hi = len;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (t[mid] < x) lo = mid + 1; else hi = mid;
    }
    size_t first = lo;
    hi = len;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (t[mid] <= x) lo = mid + 1; else hi = mid;
    }
    return lo - first;
}

static PyObject *
keys_to_list(const SmallestKeys *s, uint64_t n)
{
    PyObject *list = PyList_New(s->count);
    if (list == NULL) {
        return NULL;
    }
    for (int i = 0; i < s->count; i++) {
        PyObject *pair = Py_BuildValue("(KK)", (unsigned long long)(s->key[i] / n),
                                       (unsigned long long)(s->key[i] % n));
        if (pair == NULL) {
            Py_DECREF(list);
            return NULL;
        }
        PyList_SET_ITEM(list, i, pair);
    }
    return list;
}

static PyObject *
accel_edge_census(PyObject *self, PyObject *args)
{
    PyObject *faces_obj;
    Py_ssize_t n_vertices;
    if (!PyArg_ParseTuple(args, "On", &faces_obj, &n_vertices) || check_vertex_count(n_vertices) < 0) {
        return NULL;
    }
    Py_buffer fv;
    Py_ssize_t m;
    int size;
    if (get_faces(faces_obj, &fv, &m, &size) < 0) {
        return NULL;
    }
    if (check_indices(fv.buf, size, 3 * (size_t)m, n_vertices) < 0) {
        PyBuffer_Release(&fv);
        return NULL;
    }
    size_t n = (size_t)n_vertices, directed = 3 * (size_t)m;
    int64_t *off = (int64_t *)calloc(n + 1, sizeof(int64_t));
    int32_t *tgt = directed > SIZE_MAX / sizeof(int32_t) ? NULL
                   : (int32_t *)malloc((directed ? directed : 1) * sizeof(int32_t));
    if (off == NULL || tgt == NULL) {
        free(off);
        free(tgt);
        PyBuffer_Release(&fv);
        return PyErr_NoMemory();
    }
    uint64_t edges = 0, boundary = 0, nonmanifold = 0, misoriented = 0;
    SmallestKeys sb = {{0}, 0}, sn = {{0}, 0}, sm = {{0}, 0};
    Py_BEGIN_ALLOW_THREADS
    const void *f = fv.buf;
    for (size_t i = 0; i < (size_t)m; i++) {
        for (int k = 0; k < 3; k++) {
            off[index_at(f, size, 3 * i + k)]++;
        }
    }
    int64_t run = 0;
    for (size_t a = 0; a < n; a++) {
        int64_t d = off[a];
        off[a] = run;
        run += d;
    }
    for (size_t i = 0; i < (size_t)m; i++) {
        for (int k = 0; k < 3; k++) {
            int64_t a = index_at(f, size, 3 * i + k), b = index_at(f, size, 3 * i + (k + 1) % 3);
            tgt[off[a]++] = (int32_t)b;      /* off[a] ends as the end of a's bucket */
        }
    }
    for (size_t a = 0; a < n; a++) {
        size_t lo = a ? (size_t)off[a - 1] : 0;
        sort_bucket(tgt + lo, (size_t)off[a] - lo);
    }
    for (size_t a = 0; a < n; a++) {
        size_t lo = a ? (size_t)off[a - 1] : 0, hi = (size_t)off[a];
        size_t p = lo;
        while (p < hi) {
            int32_t b = tgt[p];
            size_t q = p + 1;
            while (q < hi && tgt[q] == b) {
                q++;
            }
            size_t fwd = q - p, bwd = 0;
            if ((size_t)b != a) {
                size_t blo = b ? (size_t)off[b - 1] : 0;
                bwd = count_sorted(tgt + blo, (size_t)off[b] - blo, (int32_t)a);
            }
            if ((size_t)b >= a || bwd == 0) {
                uint64_t u = (size_t)b < a ? (uint64_t)b : a, v = (size_t)b < a ? a : (uint64_t)b;
                uint64_t key = u * n + v;
                size_t total = fwd + bwd;
                edges++;
                if (total == 1) {
                    boundary++;
                    keep_smallest(&sb, key);
                }
                else if (total > 2) {
                    nonmanifold++;
                    keep_smallest(&sn, key);
                }
                else if (fwd == 2 || bwd == 2) {
                    misoriented++;
                    keep_smallest(&sm, key);
                }
            }
            p = q;
        }
    }
    Py_END_ALLOW_THREADS
    free(off);
    free(tgt);
    PyBuffer_Release(&fv);
    uint64_t nn = n ? n : 1;
    PyObject *lb = keys_to_list(&sb, nn), *ln = keys_to_list(&sn, nn), *lm = keys_to_list(&sm, nn);
    PyObject *result = NULL;
    if (lb && ln && lm) {
        result = Py_BuildValue("(KKKKOOO)", (unsigned long long)edges, (unsigned long long)boundary,
                               (unsigned long long)nonmanifold, (unsigned long long)misoriented, lb, ln, lm);
    }
    Py_XDECREF(lb);
    Py_XDECREF(ln);
    Py_XDECREF(lm);
    return result;
}

/* ======================================================================================================
 * 4. shell_labels
 *
 * Union-find over vertices (union by smaller index, path halving), so each root is the smallest vertex of
 * its component.  Faces are labelled by their root's rank among the roots that carry faces: shells are
 * numbered by their smallest vertex index, as checks.shell_labels does.
 * ====================================================================================================== */

static inline int32_t
find_root(int32_t *parent, int32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static PyObject *
accel_shell_labels(PyObject *self, PyObject *args)
{
    PyObject *faces_obj, *out_obj;
    Py_ssize_t n_vertices;
    if (!PyArg_ParseTuple(args, "OnO", &faces_obj, &n_vertices, &out_obj) || check_vertex_count(n_vertices) < 0) {
        return NULL;
    }
    Py_buffer fv, out;
    Py_ssize_t m;
    int size;
    if (get_faces(faces_obj, &fv, &m, &size) < 0) {
        return NULL;
    }
    if (PyObject_GetBuffer(out_obj, &out, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyBuffer_Release(&fv);
        return NULL;
    }
    int out_size = signed_int_size(&out);
    if (out_size == 0 || out.ndim != 1 || out.shape[0] != m) {
        PyErr_Format(PyExc_ValueError, "Expected `out` as a contiguous int32 or int64 array of %zd entries", m);
        goto fail;
    }
    if (check_indices(fv.buf, size, 3 * (size_t)m, n_vertices) < 0) {
        goto fail;
    }
    size_t n = (size_t)n_vertices;
    int32_t *parent = (int32_t *)malloc((n ? n : 1) * sizeof(int32_t));
    unsigned char *carries = (unsigned char *)calloc(n ? n : 1, 1);
    if (parent == NULL || carries == NULL) {
        free(parent);
        free(carries);
        PyErr_NoMemory();
        goto fail;
    }
    int64_t count = 0;
    Py_BEGIN_ALLOW_THREADS
    const void *f = fv.buf;
    for (size_t v = 0; v < n; v++) {
        parent[v] = (int32_t)v;
    }
    for (size_t i = 0; i < (size_t)m; i++) {
        int32_t a = find_root(parent, (int32_t)index_at(f, size, 3 * i));
        for (int k = 1; k < 3; k++) {
            int32_t b = find_root(parent, (int32_t)index_at(f, size, 3 * i + k));
            if (a < b) {
                parent[b] = a;
            }
            else if (b < a) {
                parent[a] = b;
                a = b;
            }
        }
    }
    for (size_t i = 0; i < (size_t)m; i++) {
        carries[find_root(parent, (int32_t)index_at(f, size, 3 * i))] = 1;
    }
    /* roots in index order get ranks 0..count-1; every vertex then maps to its root's rank */
    for (size_t v = 0; v < n; v++) {
        if (parent[v] == (int32_t)v) {
            parent[v] = carries[v] ? (int32_t)count++ : -1;
        }
        else {
            parent[v] = parent[parent[v]];   /* the root is smaller than v: already a rank */
        }
    }
    for (size_t i = 0; i < (size_t)m; i++) {
        int64_t label = parent[index_at(f, size, 3 * i)];
        if (out_size == 8) {
            ((int64_t *)out.buf)[i] = label;
        }
        else {
            ((int32_t *)out.buf)[i] = (int32_t)label;
        }
    }
    Py_END_ALLOW_THREADS
    free(parent);
    free(carries);
    PyBuffer_Release(&fv);
    PyBuffer_Release(&out);
    return PyLong_FromLongLong((long long)count);
fail:
    PyBuffer_Release(&fv);
    PyBuffer_Release(&out);
    return NULL;
}

/* ======================================================================================================
 * 5. tetra_sums
 *
 * One pass over the faces computing, per label, the sums of volume._tetra_sums (Tonon 2004; Eq. 4.11/4.13
 * of the chapter made discrete):  with p_k the corners relative to `origin`, s = p1 + p2 + p3 and
 * 6v = p1 . ((p2 - p1) x (p3 - p1)):
 *   [0]      sum v6 / 6                                           volume
 *   [1..3]   sum v6 s_i / 24                                      first moments
 *   [4..9]   sum v6 (sum_k p_ki p_kj + s_i s_j) / 120, ij = xx yy zz xy xz yz   second moments
 *   [10]     sum |(p2 - p1) x (p3 - p1)| / 2                       area
 * and the count of faces with area <= area_floor / 2.  Each sum is compensated (Knuth's TwoSum, the
 * error of every addition carried in a second word), so the result is the correctly rounded sum of the
 * per-face terms up to a few ulps whatever the face count.
 * ====================================================================================================== */

#define NSUMS 11

static inline void
two_sum_add(double *acc, double x)
{
    double s = acc[0] + x;
    double bp = s - acc[0];
    acc[1] += (acc[0] - (s - bp)) + (x - bp);
    acc[0] = s;
}

static PyObject *
accel_tetra_sums(PyObject *self, PyObject *args)
{
    PyObject *vert_obj, *faces_obj, *labels_obj, *sums_obj, *zero_obj;
    double ox, oy, oz, area_floor;
    if (!PyArg_ParseTuple(args, "OO(ddd)dOOO", &vert_obj, &faces_obj, &ox, &oy, &oz, &area_floor, &labels_obj,
                          &sums_obj, &zero_obj)) {
        return NULL;
    }
    Py_buffer vv, fv, lv, sv, zv;
    double *acc = NULL;
    PyObject *result = NULL;
    int have_labels = labels_obj != Py_None, label_size = 0, size;
    Py_ssize_t m;
    if (PyObject_GetBuffer(vert_obj, &vv, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (get_faces(faces_obj, &fv, &m, &size) < 0) {
        PyBuffer_Release(&vv);
        return NULL;
    }
    if (PyObject_GetBuffer(sums_obj, &sv, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyBuffer_Release(&vv);
        PyBuffer_Release(&fv);
        return NULL;
    }
    if (PyObject_GetBuffer(zero_obj, &zv, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyBuffer_Release(&vv);
        PyBuffer_Release(&fv);
        PyBuffer_Release(&sv);
        return NULL;
    }
    if (have_labels && PyObject_GetBuffer(labels_obj, &lv, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        have_labels = 0;
        goto fail;
    }
    if (native_code(vv.format) != 'd' || vv.itemsize != 8 || vv.ndim != 2 || vv.shape[1] != 3) {
        PyErr_SetString(PyExc_ValueError, "Expected `vertices` as a C-contiguous (n, 3) float64 array");
        goto fail;
    }
    if (native_code(sv.format) != 'd' || sv.itemsize != 8 || sv.ndim != 2 || sv.shape[1] != NSUMS
        || sv.shape[0] < 1) {
        PyErr_SetString(PyExc_ValueError, "Expected `sums` as a C-contiguous (n_labels, 11) float64 array");
        goto fail;
    }
    Py_ssize_t n_labels = sv.shape[0];
    if (signed_int_size(&zv) != 8 || zv.ndim != 1 || zv.shape[0] != n_labels) {
        PyErr_SetString(PyExc_ValueError, "Expected `zero` as a contiguous int64 array of n_labels entries");
        goto fail;
    }
    if (have_labels) {
        label_size = signed_int_size(&lv);
        if (label_size == 0 || lv.ndim != 1 || lv.shape[0] != m) {
            PyErr_SetString(PyExc_ValueError, "Expected `labels` as a contiguous int32 or int64 (m,) array");
            goto fail;
        }
    }
    else if (n_labels != 1) {
        PyErr_SetString(PyExc_ValueError, "Expected `labels` when n_labels > 1");
        goto fail;
    }
    Py_ssize_t n = vv.shape[0];
    if (check_indices(fv.buf, size, 3 * (size_t)m, n) < 0) {
        goto fail;
    }
    if (n_labels > PY_SSIZE_T_MAX / (Py_ssize_t)(2 * NSUMS * sizeof(double))) {
        PyErr_NoMemory();
        goto fail;
    }
    acc = (double *)calloc((size_t)n_labels * 2 * NSUMS, sizeof(double));
    if (acc == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    int64_t *zero = (int64_t *)zv.buf;
    memset(zero, 0, (size_t)n_labels * sizeof(int64_t));
    Py_ssize_t bad_label = -1;
    const double *v = (const double *)vv.buf;
    const void *f = fv.buf, *lab = have_labels ? lv.buf : NULL;
    double half_floor = 0.5 * area_floor;
    Py_BEGIN_ALLOW_THREADS
    for (size_t i = 0; i < (size_t)m; i++) {
        int64_t l = 0;
        if (lab != NULL) {
            l = index_at(lab, label_size, i);
            if (l < 0 || l >= n_labels) {
                bad_label = (Py_ssize_t)i;
                break;
            }
        }
        const double *pa = v + 3 * index_at(f, size, 3 * i);
        const double *pb = v + 3 * index_at(f, size, 3 * i + 1);
        const double *pc = v + 3 * index_at(f, size, 3 * i + 2);
        double a0 = pa[0] - ox, a1 = pa[1] - oy, a2 = pa[2] - oz;
        double b0 = pb[0] - ox, b1 = pb[1] - oy, b2 = pb[2] - oz;
        double c0 = pc[0] - ox, c1 = pc[1] - oy, c2 = pc[2] - oz;
        double e10 = b0 - a0, e11 = b1 - a1, e12 = b2 - a2;
        double e20 = c0 - a0, e21 = c1 - a1, e22 = c2 - a2;
        double n0 = e11 * e22 - e12 * e21;
        double n1 = e12 * e20 - e10 * e22;
        double n2 = e10 * e21 - e11 * e20;
        double v6 = a0 * n0 + a1 * n1 + a2 * n2;
        double area = 0.5 * sqrt(n0 * n0 + n1 * n1 + n2 * n2);
        double s0 = a0 + b0 + c0, s1 = a1 + b1 + c1, s2 = a2 + b2 + c2;
        double *x = acc + (size_t)l * 2 * NSUMS;
        if (area <= half_floor) {
            zero[l]++;
        }
        two_sum_add(x + 0, v6 / 6.0);
        two_sum_add(x + 2, v6 * s0 / 24.0);
        two_sum_add(x + 4, v6 * s1 / 24.0);
        two_sum_add(x + 6, v6 * s2 / 24.0);
        two_sum_add(x + 8, v6 * (a0 * a0 + b0 * b0 + c0 * c0 + s0 * s0) / 120.0);
        two_sum_add(x + 10, v6 * (a1 * a1 + b1 * b1 + c1 * c1 + s1 * s1) / 120.0);
        two_sum_add(x + 12, v6 * (a2 * a2 + b2 * b2 + c2 * c2 + s2 * s2) / 120.0);
        two_sum_add(x + 14, v6 * (a0 * a1 + b0 * b1 + c0 * c1 + s0 * s1) / 120.0);
        two_sum_add(x + 16, v6 * (a0 * a2 + b0 * b2 + c0 * c2 + s0 * s2) / 120.0);
        two_sum_add(x + 18, v6 * (a1 * a2 + b1 * b2 + c1 * c2 + s1 * s2) / 120.0);
        two_sum_add(x + 20, area);
    }
    Py_END_ALLOW_THREADS
    if (bad_label >= 0) {
        PyErr_Format(PyExc_ValueError, "Expected labels in 0..%zd, got %lld at position %zd", n_labels - 1,
                     (long long)index_at(lab, label_size, (size_t)bad_label), bad_label);
        goto fail;
    }
    double *sums = (double *)sv.buf;
    for (Py_ssize_t k = 0; k < n_labels * NSUMS; k++) {
        sums[k] = acc[2 * k] + acc[2 * k + 1];
    }
    result = Py_None;
    Py_INCREF(result);
fail:
    free(acc);
    PyBuffer_Release(&vv);
    PyBuffer_Release(&fv);
    PyBuffer_Release(&sv);
    PyBuffer_Release(&zv);
    if (have_labels) {
        PyBuffer_Release(&lv);
    }
    return result;
}

/* ======================================================================================================
 * module
 * ====================================================================================================== */

static PyMethodDef accel_methods[] = {
    {"edge_census", accel_edge_census, METH_VARARGS,
     "edge_census(faces, n_vertices) -> (edges, boundary, nonmanifold, misoriented, sample_boundary, "
     "sample_nonmanifold, sample_misoriented)\n\nEdge census of (m, 3) int32/int64 faces; each sample is a "
     "list of up to 5 (u, v) vertex pairs, u < v, smallest u * n + v first."},
    {"shell_labels", accel_shell_labels, METH_VARARGS,
     "shell_labels(faces, n_vertices, out) -> count\n\nWrite each face's shell (connected by shared "
     "vertices), numbered by the shell's smallest vertex index, into `out` (m,) int32/int64."},
    {"tetra_sums", accel_tetra_sums, METH_VARARGS,
     "tetra_sums(vertices, faces, origin, area_floor, labels, sums, zero)\n\nCompensated signed-tetrahedron "
     "sums per label into sums (L, 11) float64 [vol, first xyz, second xx yy zz xy xz yz, area] and zero "
     "(L,) int64 (faces with area <= area_floor / 2); labels (m,) int or None when L == 1."},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef accel_module = {
    PyModuleDef_HEAD_INIT,
    "inertia_tool._accel",
    "Optional C kernels of inertia_tool's engine (weld, edge census, shells, integration); see _accel.c.",
    -1,
    accel_methods,
};

PyMODINIT_FUNC
PyInit__accel(void)
{
    if (PyType_Ready(&WelderType) < 0) {
        return NULL;
    }
    PyObject *mod = PyModule_Create(&accel_module);
    if (mod == NULL) {
        return NULL;
    }
    Py_INCREF(&WelderType);
    if (PyModule_AddObject(mod, "Welder", (PyObject *)&WelderType) < 0) {
        Py_DECREF(&WelderType);
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
