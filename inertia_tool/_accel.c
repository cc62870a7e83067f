/*
 * inertia_tool._accel -- optional C kernels for the engine's hot loops.
 *
 * Written against the CPython C API and the buffer protocol only (no numpy headers), so it builds with a
 * C compiler and the Python headers.  Every function here has a pure-numpy twin that stays the reference
 * (inertia_tool/mesh/weld.py, mesh/checks.py, mass/volume.py); the Python modules call these only when this module
 * imports and INERTIA_TOOL_NO_ACCEL is not set.  Results are identical to the numpy path (welding, edge
 * census, shell labels) or equal to round-off (the compensated integration sums).
 *
 * Sections:
 *   1. buffers     -- format / shape checks shared by the kernels
 *   1b. threads    -- run_parallel, the work tickets
 *   2. Welder      -- streaming exact weld of float32 or float64 points (mesh/weld.py)
 *   2b. PartWelder -- the same weld of float32 points by radix partition, on several threads
 *                      (and pool_take / pool_give: the weld's and the census's scratch mappings, kept for
 *                      the next call; Scratch, a buffer on one, for the weld's output arrays)
 *   3. edge_census -- boundary / non-manifold / misoriented edges (mesh/checks.edge_topology)
 *   4. shell_labels-- union-find connected components of faces (mesh/checks.shell_labels)
 *   4c. census_shells -- the census and the shell labels from one adjacency, on several threads
 *                      (mesh/checks.census_and_shells, and the C path of edge_topology and shell_labels)
 *   5. tetra_sums  -- signed-tetrahedron volume integrals with compensated sums (mass/volume._tetra_sums);
 *                     roundoff_sums, the per-face sums of their round-off bound (integrals.roundoff_bounds)
 *   6. bounds      -- bounding box and finiteness of the vertices in one pass (mass/volume.bounding_box)
 *   7. split_steps -- the splitting integrator's step loop (dynamics/splitting.py)
 *   8. contact_scan -- faces meeting beyond what they share: hierarchy of boxes + exact pair classification
 *                      (mesh/intersect.py)
 *   13. winding_tree -- the generalized winding number by a treecode, with its error bound (mesh/winding.py)
 *
 * Safety: every index read from an array is bounds-checked before use, sizes are checked against
 * overflow before allocation, NaN coordinates are hashed by their bit pattern (never compared as floats),
 * and the GIL is released around every loop over faces or points (buffers stay pinned by their views).
 *
 * Threads (section 1b): edge_census, census_shells, tetra_sums and bounds take a `threads` count (default 1)
 * and split their work so that the result is identical whatever that count is; only the speed changes.  The
 * one-table weld and the separate shell_labels / edge_shell_labels run on one thread; PartWelder (section
 * 2b), the weld of large float32 streams, and census_shells (4c), which the Python side uses for the shell
 * labels, take a `threads` count.
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

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
 * 1b. threads
 *
 * run_parallel(nt, fn, ctx) runs fn(ctx, t, nt) for t = 0..nt-1, t = 0 on the calling thread, and returns
 * when all are done (the GIL is released by the caller; no task touches a Python object).  If a thread
 * cannot be started, its share runs on the calling thread instead, so the result never depends on how many
 * threads actually ran: every kernel splits its work by `t` and `nt` only, and combines the parts in a
 * fixed order.  next_ticket hands out work items to whichever thread is free (so a thread slowed by other
 * processes delays no one).
 * ====================================================================================================== */

#define MAX_THREADS 16

typedef void (*task_fn)(void *ctx, int t, int nt);

typedef struct {
    task_fn fn;
    void *ctx;
    int t, nt;
} TaskArg;

/* The platform's threads: thread_start(&handle, arg) runs task_entry(arg) on a new thread and returns
 * nonzero when it started; thread_join(handle) waits for it.  next_ticket(&counter) is an atomic
 * fetch-and-increment. */
#if defined(_WIN32)
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN     /* no rpc.h / ole2.h: fewer plain words (small, interface, ...) become macros */
#endif
#include <windows.h>

typedef HANDLE thread_handle;

static DWORD WINAPI
task_entry(LPVOID arg)
{
    TaskArg *a = (TaskArg *)arg;
    a->fn(a->ctx, a->t, a->nt);
    return 0;
}

static int
thread_start(thread_handle *handle, TaskArg *arg)
{
    *handle = CreateThread(NULL, 0, task_entry, arg, 0, NULL);
    return *handle != NULL;
}

static void
thread_join(thread_handle handle)
{
    WaitForSingleObject(handle, INFINITE);
    CloseHandle(handle);
}

static inline int32_t
next_ticket(int32_t *counter)
{
    return (int32_t)InterlockedIncrement((volatile LONG *)counter) - 1;
}

#else
#include <pthread.h>

typedef pthread_t thread_handle;

static void *
task_entry(void *arg)
{
    TaskArg *a = (TaskArg *)arg;
    a->fn(a->ctx, a->t, a->nt);
    return NULL;
}

static int
thread_start(thread_handle *handle, TaskArg *arg)
{
    return pthread_create(handle, NULL, task_entry, arg) == 0;
}

static void
thread_join(thread_handle handle)
{
    pthread_join(handle, NULL);
}

static inline int32_t
next_ticket(int32_t *counter)
{
    return __atomic_fetch_add(counter, 1, __ATOMIC_RELAXED);
}
#endif

static void
run_parallel(int nt, task_fn fn, void *ctx)
{
    thread_handle handle[MAX_THREADS];
    TaskArg arg[MAX_THREADS];
    int started[MAX_THREADS] = {0};
    if (nt > MAX_THREADS) nt = MAX_THREADS;
    if (nt < 1) nt = 1;
    for (int t = 1; t < nt; t++) {
        arg[t].fn = fn; arg[t].ctx = ctx; arg[t].t = t; arg[t].nt = nt;
        started[t] = thread_start(&handle[t], &arg[t]);
    }
    fn(ctx, 0, nt);
    for (int t = 1; t < nt; t++) {
        if (started[t]) {
            thread_join(handle[t]);
        }
        else {
            fn(ctx, t, nt);      /* could not start: its share runs here */
        }
    }
}

/* Start of part t of n items split into nt contiguous parts. */
static inline size_t
part_start(size_t n, int t, int nt)
{
    return (size_t)((unsigned long long)n * (unsigned)t / (unsigned)nt);
}

/* The `threads` argument of a kernel: 1 .. MAX_THREADS, and 1 below `min_items` items (a thread costs more
 * than it saves on small inputs). */
static int
thread_count(int requested, size_t items, size_t min_items)
{
    if (requested < 1 || items < min_items) {
        return 1;
    }
    return requested > MAX_THREADS ? MAX_THREADS : requested;
}

/* ======================================================================================================
 * 2. Welder: streaming exact weld
 *
 * An open-addressing hash table (linear probing, load factor <= 1/2, doubled when full) maps the exact bit
 * pattern of a point -- three float32 or three float64 words, -0.0 folded onto +0.0 -- to a vertex id
 * assigned in order of first appearance.  The table stores only ids; the keys (the full 12 or 24 bytes)
 * live in an array indexed by id and every probe compares the full key, so two different points can never
 * share a vertex whatever the hash does.
 *
 * A shared corner recurs within a few triangles in the files people have (in a 5M-face sphere, 87 % of
 * repeats within 64 corners, 98 % within 4,096), so a small direct-mapped cache of the points seen last is
 * checked (full key) before the table: 82 % of that sphere's lookups end there.
 *
 * One thread: a version that split the points over per-thread tables (hash-partitioned, renumbered in
 * stream order afterwards) gave the same ids but took twice the CPU time of this loop on two cores, and no
 * less wall time; the other kernels are threaded.
 * ====================================================================================================== */

#define MAX_VERTICES ((size_t)INT32_MAX - 1)
#define WELD_RECENT 4096                      /* entries of the recent-point cache */
#define WELD_INITIAL_MAX ((size_t)1 << 24)    /* slots allocated up front, at most (the table grows past it) */
#define WELD_AHEAD 64                         /* prefetch distance (points) of the feed loop */
#define WELD_RING 128                         /* hashes kept for it: a power of two > WELD_AHEAD */

enum { WELD_OK = 0, WELD_NOMEM = 1, WELD_TOO_MANY = 2 };

typedef struct { uint32_t k[3]; uint32_t id; } Recent32;   /* id = vertex id + 1; 0 = empty */
typedef struct { uint64_t k[3]; uint64_t id; } Recent64;

typedef struct {
    PyObject_HEAD
    int wide;              /* 0: float32 keys (3 x 32 bits); 1: float64 keys (3 x 64 bits) */
    int busy;              /* a feed or vertices_into is running with the GIL released */
    uint32_t *slots;       /* vertex id + 1, 0 = empty; mask + 1 entries */
    size_t mask;
    void *keys;            /* keys_cap keys of 3 words each, in vertex-id order */
    size_t keys_cap;
    void *recent;          /* WELD_RECENT Recent32 or Recent64 */
    size_t count;          /* vertices so far */
    uint64_t points;       /* points fed so far */
} WelderObject;

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

static int
welder_grow_keys(WelderObject *w)
{
    size_t cap = w->keys_cap ? 2 * w->keys_cap : 1024, kb = w->wide ? 24 : 12;
    if (cap > MAX_VERTICES + 1) {
        cap = MAX_VERTICES + 1;
    }
    if (cap > SIZE_MAX / kb) {
        return WELD_NOMEM;
    }
    void *keys = realloc(w->keys, cap * kb);
    if (keys == NULL) {
        return WELD_NOMEM;
    }
    w->keys = keys;
    w->keys_cap = cap;
    return WELD_OK;
}

/* Table growth, lookup-or-insert and the feed loop for one key type. */
#define DEFINE_WELD(SUFFIX, KEY_T, RECENT_T, HASH, NEG_ZERO)                                              \
static int                                                                                                \
grow_##SUFFIX(WelderObject *w)                                                                            \
{                                                                                                         \
    size_t capacity = w->mask + 1;                                                                        \
    if (capacity > SIZE_MAX / 2 / sizeof(uint32_t)) {                                                     \
        return WELD_NOMEM;                                                                                \
    }                                                                                                     \
    uint32_t *slots = (uint32_t *)calloc(2 * capacity, sizeof(uint32_t));                                 \
    if (slots == NULL) {                                                                                  \
        return WELD_NOMEM;                                                                                \
    }                                                                                                     \
    size_t mask = 2 * capacity - 1;                                                                       \
    const KEY_T *keys = (const KEY_T *)w->keys;                                                           \
    for (size_t id = 0; id < w->count; id++) {                                                            \
        size_t i = (size_t)HASH(keys + 3 * id) & mask;                                                    \
        while (slots[i] != 0) {                                                                           \
            i = (i + 1) & mask;                                                                           \
        }                                                                                                 \
        slots[i] = (uint32_t)(id + 1);                                                                    \
    }                                                                                                     \
    free(w->slots);                                                                                       \
    w->slots = slots;                                                                                     \
    w->mask = mask;                                                                                       \
    return WELD_OK;                                                                                       \
}                                                                                                         \
                                                                                                          \
static inline int                                                                                         \
lookup_##SUFFIX(WelderObject *w, const KEY_T *key, uint64_t h, int32_t *id_out)                           \
{                                                                                                         \
    const KEY_T *keys = (const KEY_T *)w->keys;                                                           \
    size_t i = (size_t)h & w->mask;                                                                       \
    while (w->slots[i] != 0) {          /* the load factor stays <= 1/2: an empty slot exists */          \
        const KEY_T *o = keys + 3 * (size_t)(w->slots[i] - 1);                                            \
        if (o[0] == key[0] && o[1] == key[1] && o[2] == key[2]) {                                         \
            *id_out = (int32_t)(w->slots[i] - 1);                                                         \
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
        int st = grow_##SUFFIX(w);                                                                        \
        if (st != WELD_OK) {                                                                              \
            return st;                                                                                    \
        }                                                                                                 \
        i = (size_t)h & w->mask;                                                                          \
        while (w->slots[i] != 0) {                                                                        \
            i = (i + 1) & w->mask;                                                                        \
        }                                                                                                 \
    }                                                                                                     \
    memcpy((KEY_T *)w->keys + 3 * w->count, key, 3 * sizeof(KEY_T));                                     \
    w->slots[i] = (uint32_t)(w->count + 1);                                                               \
    *id_out = (int32_t)w->count;                                                                          \
    w->count++;                                                                                           \
    return WELD_OK;                                                                                       \
}                                                                                                         \
                                                                                                          \
/* Weld point (i0, i1) of a (n0, n1, 3) strided array for every i0, i1 in C order into ids[].              \
 * Software pipelined: the point WELD_AHEAD places ahead is hashed and, when the recent-point cache does    \
 * not hold it, its table slot is prefetched; half as far ahead the slot is read and the key it points to  \
 * prefetched; so the two dependent cache misses of a table lookup overlap with the work on other points.  \
 * Prefetches are only hints: the ids are those of the plain loop. */                                     \
static inline void                                                                                        \
load_key_##SUFFIX(const char *p, Py_ssize_t sc, KEY_T *key)                                               \
{                                                                                                         \
    for (int c = 0; c < 3; c++) {                                                                         \
        memcpy(&key[c], p + c * sc, sizeof(KEY_T));                                                       \
        if (key[c] == (NEG_ZERO)) {                                                                       \
            key[c] = 0;                                                                                   \
        }                                                                                                 \
    }                                                                                                     \
}                                                                                                         \
                                                                                                          \
static int                                                                                                \
feed_##SUFFIX(WelderObject *w, const char *base, Py_ssize_t n0, Py_ssize_t n1, Py_ssize_t s0,             \
              Py_ssize_t s1, Py_ssize_t sc, int32_t *ids)                                                 \
{                                                                                                         \
    uint64_t ring[WELD_RING];                                                                             \
    Py_ssize_t total = n0 * n1, a0 = 0, a1 = 0, i0 = 0, i1 = 0;                                           \
    /* hashes of the first WELD_AHEAD points; (a0, a1) then walks WELD_AHEAD points ahead of (i0, i1) */  \
    for (Py_ssize_t k = 0; k < total && k < WELD_AHEAD; k++) {                                            \
        KEY_T key[3];                                                                                     \
        load_key_##SUFFIX(base + a0 * s0 + a1 * s1, sc, key);                                             \
        ring[k & (WELD_RING - 1)] = HASH(key);                                                            \
        if (++a1 == n1) { a1 = 0; a0++; }                                                                 \
    }                                                                                                     \
    for (Py_ssize_t k = 0; k < total; k++) {                                                              \
        if (k + WELD_AHEAD < total) {                                                                     \
            KEY_T ka[3];                                                                                  \
            load_key_##SUFFIX(base + a0 * s0 + a1 * s1, sc, ka);                                          \
            if (++a1 == n1) { a1 = 0; a0++; }                                                             \
            uint64_t ha = HASH(ka);                                                                       \
            ring[(k + WELD_AHEAD) & (WELD_RING - 1)] = ha;                                                \
            const RECENT_T *ra = (const RECENT_T *)w->recent + ((ha >> 40) & (WELD_RECENT - 1));          \
            if (!(ra->id != 0 && ra->k[0] == ka[0] && ra->k[1] == ka[1] && ra->k[2] == ka[2])) {          \
                __builtin_prefetch(&w->slots[(size_t)ha & w->mask]);                                      \
            }                                                                                             \
        }                                                                                                 \
        if (k + WELD_AHEAD / 2 < total) {                                                                 \
            uint32_t sid = w->slots[(size_t)ring[(k + WELD_AHEAD / 2) & (WELD_RING - 1)] & w->mask];      \
            if (sid != 0) {                                                                               \
                __builtin_prefetch((const KEY_T *)w->keys + 3 * (size_t)(sid - 1));                       \
            }                                                                                             \
        }                                                                                                 \
        KEY_T key[3];                                                                                     \
        load_key_##SUFFIX(base + i0 * s0 + i1 * s1, sc, key);                                             \
        if (++i1 == n1) { i1 = 0; i0++; }                                                                 \
        uint64_t h = ring[k & (WELD_RING - 1)];                                                           \
        RECENT_T *r = (RECENT_T *)w->recent + ((h >> 40) & (WELD_RECENT - 1));                            \
        if (r->id != 0 && r->k[0] == key[0] && r->k[1] == key[1] && r->k[2] == key[2]) {                  \
            ids[k] = (int32_t)(r->id - 1);                                                                \
            continue;                                                                                     \
        }                                                                                                 \
        int status = lookup_##SUFFIX(w, key, h, &ids[k]);                                                 \
        if (status != WELD_OK) {                                                                          \
            return status;                                                                                \
        }                                                                                                 \
        r->k[0] = key[0];                                                                                 \
        r->k[1] = key[1];                                                                                 \
        r->k[2] = key[2];                                                                                 \
        r->id = (uint32_t)ids[k] + 1;                                                                     \
    }                                                                                                     \
    return WELD_OK;                                                                                       \
}

DEFINE_WELD(32, uint32_t, Recent32, hash32, 0x80000000U)
DEFINE_WELD(64, uint64_t, Recent64, hash64, 0x8000000000000000ULL)

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
    size_t capacity = 1024;     /* expected_vertices is a hint: the table grows past WELD_INITIAL_MAX */
    while (capacity < 2 * (size_t)expected + 2 && capacity < WELD_INITIAL_MAX) {
        capacity *= 2;
    }
    w->slots = (uint32_t *)calloc(capacity, sizeof(uint32_t));
    w->recent = calloc(WELD_RECENT, w->wide ? sizeof(Recent64) : sizeof(Recent32));
    w->keys_cap = capacity / 2;
    w->keys = malloc(w->keys_cap * (w->wide ? 24 : 12));
    if (w->slots == NULL || w->recent == NULL || w->keys == NULL) {
        free(w->slots);
        free(w->recent);
        free(w->keys);
        w->slots = NULL;
        w->recent = w->keys = NULL;
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
    free(w->recent);
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
    int status;
    w->busy = 1;
    Py_BEGIN_ALLOW_THREADS
    status = w->wide ? feed_64(w, (const char *)pts.buf, n0, n1, s0, s1, sc, (int32_t *)out.buf)
                     : feed_32(w, (const char *)pts.buf, n0, n1, s0, s1, sc, (int32_t *)out.buf);
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
    w->busy = 1;                        /* the GIL is released: a feed() meanwhile could move the keys */
    Py_BEGIN_ALLOW_THREADS
    if (w->wide && w->count > 0) {      /* no memcpy of 0 bytes: out may be NULL then */
        memcpy(v, w->keys, w->count * 24);
    }
    else {
        const float *f = (const float *)w->keys;
        for (size_t i = 0; i < 3 * w->count; i++) {
            v[i] = (double)f[i];
        }
    }
    Py_END_ALLOW_THREADS
    w->busy = 0;
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

/* ------------------------------------------------------------------------------------------------------
 * 2b. PartWelder: the same exact weld of float32 points by radix partition, on several threads
 *
 * The Welder above probes one table of all the vertices: past a few million vertices that table lives in
 * memory and every lookup the recent-point cache misses costs one or two cache misses (72 ns per corner on
 * a 10M-face torus).  PartWelder splits the work so that every table fits in a core's L2 cache:
 *
 *   feed     each point is hashed (pw_hash, -0.0 folded onto +0.0); one that the thread's cache of the
 *            16,384 points seen last holds (full key compared) refers to that earlier corner; any other is
 *            copied with its corner number into one of 2**bits buckets chosen by the hash's top bits (a
 *            radix partition: per thread a histogram of its half of the chunk while staging its misses in
 *            order, then a scatter of the staged misses); the output index keeps each point's bucket or
 *            reference until output;
 *   finish   each bucket (threads take the next bucket free) is welded in a small table of entry numbers
 *            (the table compares a point with the entry of each vertex's first point, in place: no copy of
 *            the vertices): equal keys always share a bucket, and a bucket holds its points in file order
 *            (chunks in order, a chunk's parts in order, a part's points in order), so the first point of
 *            each distinct key in its bucket is its first corner in the whole stream; that corner is marked in
 *            a bitmap of all corners; each point's entry then names its vertex's first corner;
 *   output   a vertex's number is the count of marked corners before its first corner (first appearance
 *            order, exactly the Welder's numbering); every corner's number is gathered in file order through
 *            its bucket's cursor (a vertex's first corner writes the vertex; a corner whose vertex came first
 *            earlier in its part copies that corner's number, any other counts the marks before that first
 *            corner), or copied from the earlier corner it refers to, which is in the same part: done already.
 *
 * The result is the Welder's bit for bit (same keys, same equality, same numbering); only the order of the
 * work differs, and no step depends on which thread did it.  Memory until output returns: 16 bytes (key,
 * corner) per point the recent-point cache did not hold -- at most 48 per triangle, about the size of the
 * binary STL (50 per triangle), 18-52 % of that on the benchmark meshes; the arena is reserved for
 * all points but only the pages written are resident -- plus, while finishing, a table of 4 bytes per slot
 * per thread (at most 2**17 slots), a bit per point per thread, and while feeding 16 bytes per point of one
 * chunk (the staged misses; 6 MB for the reader's chunks).  (Until issue 25's fifth pass the buckets were
 * welded into per-thread copies of their vertices, 16 bytes per vertex more: 42 MB of fresh pages on the
 * 5.24M-face icosphere, whose zeroing by the kernel cost about as much as welding into them.)  Since its
 * sixth pass a chunk's entries are packed part after part (before, each part's started at its first point's
 * place, and the hits' gaps between them were resident too: 361 instead of 236 MiB on the 10M-face torus),
 * and output gives the entries' pages back chunk by chunk as it gathers (pw_release_gathered), so the
 * vertices it writes take the place of the entries instead of adding to them: the weld's peak on that torus
 * 626 -> 410 MiB, 0.86x the file.
 * The Welder's table is about 12 bytes per triangle.
 * ------------------------------------------------------------------------------------------------------ */

#define PW_MAX_BITS 12
/* Entries of each feeding thread's recent-point cache (16 bytes each: 256 kB, about a core's L2).  4,096 (the
 * Welder's) until issue 25's sixth pass: on the benchmark torus, whose rows of quads reuse the row before's
 * corners ~3,200 distinct points later, 52 % of the points reached a bucket; at 16,384, 40 % (icosphere
 * 17.8 -> 17.2 %), and the weld took 20-30 % less CPU time (A/B in one process, docs/performance.md). */
#define PW_RECENT 16384
#define PW_TARGET_POINTS ((size_t)1 << 15)   /* points per bucket aimed at: table and keys stay in L2 */

typedef struct { uint32_t k[3]; uint32_t corner; } PwEntry;   /* corner: after finish, its vertex's first
                                                                 * corner */

typedef struct {
    PwEntry *entries;      /* the chunk's misses, part after part (part t's at [off_t[0], off_t[B])) */
    int32_t *bucket;       /* bucket of each point of the chunk, in file order (its part of `index`) */
    uint32_t *off;         /* nt * (B + 1): start of bucket b of part t at off[t * (B + 1) + b] */
    uint32_t corner0;      /* the chunk's first corner */
    uint32_t size;         /* its points */
    int nt;
} PwChunk;

typedef struct {
    PyObject_HEAD
    int threads, bits, busy, state;    /* state: 0 feeding, 1 finished, 2 output written (released) */
    size_t n_points, points;
    PwEntry *entries;                  /* n_points entries: chunk after chunk (a big-page arena) */
    size_t entries_used;               /* entries of the chunks so far */
    size_t released;                   /* bytes of the arena, from its start, given back by the gather */
    size_t partitioned;                /* points copied into the buckets (not found in a recent cache) */
    Recent32 *recent;                  /* per thread: PW_RECENT points seen last in the part it feeds */
    PwEntry *stage;                    /* the misses of the chunk being fed, before the scatter */
    size_t stage_cap, stage_bytes;     /* its entries; its mapping's size */
    Py_buffer index;                   /* the caller's int32 output: bucket numbers until output() */
    int has_index;
    size_t arena_bytes;
    PwChunk *chunks;
    size_t n_chunks, chunks_cap;
    uint32_t *nv;                      /* per bucket: its vertices */
    uint64_t *mark[MAX_THREADS];       /* per thread: bit c set when corner c is a vertex's first */
    uint32_t *rank;                    /* per mark word: marked corners before it */
    size_t count;
} PartWelderObject;

/* A large zeroed-on-demand allocation, backed by 2 MB pages where the kernel offers them: the points of a
 * 10M-face file are 540 MB, and 4 kB pages would cost one page fault per 227 points. */
static void *
map_fresh(size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    void *p = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) {
        return NULL;
    }
    madvise(p, bytes, MADV_HUGEPAGE);     /* a hint: without it, ordinary pages */
    return p;
#else
    return malloc(bytes);
#endif
}

static void
arena_free(void *p, size_t bytes)
{
    if (p == NULL) {
        return;
    }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    munmap(p, bytes);
#else
    (void)bytes;
    free(p);
#endif
}

/* The weld's and the census's scratch mappings, kept for the next call in the process.  Fresh anonymous
 * pages cost the kernel a page fault and a zeroing each (on a 10M-face file about a third of the weld's CPU
 * time went to clear_page in the kernel); a batch or a second analysis in the same process reuses the
 * pages instead.  pool_take(&bytes) returns a kept mapping of at least `bytes` (its real size back in
 * `bytes`: give that to pool_give) or a fresh map_fresh; its contents are undefined (every user writes
 * before it reads).  Of the kept mappings large enough it takes the one whose written pages cover most of
 * `bytes` (then the smallest): a mapping of which the last user wrote only the start is a poor choice for a
 * user who writes all of it (a census taking the weld's vertex list, 240 MB mapped and 40 MB written, for
 * its 240 MB of words faulted in 200 MB of fresh pages and raised the analysis's peak by that).  Written
 * pages past `bytes` are given back to the kernel (MADV_DONTNEED) when taken, so that a small user does
 * not carry a large user's resident pages through the kernels after it.  pool_give(p, bytes) (written:
 * all of it) or pool_give_used(p, bytes, used) (the first `used` bytes) keeps the mapping when it fits in
 * POOL_SLOTS and POOL_MAX_BYTES, and tells the kernel it may take the pages back under memory pressure
 * (MADV_FREE: the pages stay resident and reusable until then; reading one taken back gives zeros), else
 * unmaps it.  Below POOL_HEAP_BYTES, pool_take gives a heap block (malloc) and pool_give frees it.
 * pool_drain() unmaps them all (accel.release_buffers()).  A mutex guards the slots: kernels free
 * their scratch with the GIL released. */
#define POOL_SLOTS 12
#define POOL_MIN_BYTES ((size_t)1 << 21)          /* below this, plain map_fresh / arena_free (tests lower
                                                     it with set_pool_floor to reuse small mappings too) */
#define POOL_MAX_BYTES ((size_t)3 << 30)          /* kept in all, at most */
#define POOL_HEAP_BYTES ((size_t)1 << 20)         /* below this, the heap (malloc / free), never a mapping: a
                                                     12-face census made 4 mmap, 4 munmap and 8 madvise calls
                                                     (ct_alloc's rule, section 8); decided by the size alone, so
                                                     pool_give knows where a block came from */

static struct { void *p; size_t bytes, used; } pool_slot[POOL_SLOTS];   /* used: bytes written, from the start */
static size_t pool_kept, pool_floor = POOL_MIN_BYTES;
#if defined(_WIN32)
static SRWLOCK pool_lock_ = SRWLOCK_INIT;
#define POOL_LOCK() AcquireSRWLockExclusive(&pool_lock_)
#define POOL_UNLOCK() ReleaseSRWLockExclusive(&pool_lock_)
#else
static pthread_mutex_t pool_lock_ = PTHREAD_MUTEX_INITIALIZER;
#define POOL_LOCK() pthread_mutex_lock(&pool_lock_)
#define POOL_UNLOCK() pthread_mutex_unlock(&pool_lock_)

/* fork() while another thread holds the lock would leave it locked in the child for good: the lock is taken
 * around fork (registered with pthread_atfork when the module loads), so the child starts with it free */
static void pool_before_fork(void) { pthread_mutex_lock(&pool_lock_); }
static void pool_after_fork(void) { pthread_mutex_unlock(&pool_lock_); }
#endif

static void *
pool_take(size_t *bytes)
{
    size_t want = *bytes ? *bytes : 1, best_reuse = 0;
    int best = -1;
    if (want < POOL_HEAP_BYTES) {
        *bytes = want;
        return malloc(want);
    }
    POOL_LOCK();
    if (want >= pool_floor) {
        for (int i = 0; i < POOL_SLOTS; i++) {
            if (pool_slot[i].p == NULL || pool_slot[i].bytes < want) {
                continue;
            }
            size_t reuse = pool_slot[i].used < want ? pool_slot[i].used : want;
            if (best < 0 || reuse > best_reuse || (reuse == best_reuse && pool_slot[i].bytes < pool_slot[best].bytes)) {
                best = i;
                best_reuse = reuse;
            }
        }
    }
    if (best >= 0) {
        void *p = pool_slot[best].p;
        size_t used = pool_slot[best].used;
        *bytes = pool_slot[best].bytes;
        pool_kept -= pool_slot[best].bytes;
        pool_slot[best].p = NULL;
        pool_slot[best].bytes = pool_slot[best].used = 0;
        POOL_UNLOCK();
#if defined(__linux__) && defined(MADV_DONTNEED)
        size_t keep = (want + 4095) & ~(size_t)4095;
        if (used > keep && keep < *bytes) {
            madvise((char *)p + keep, (used < *bytes ? used : *bytes) - keep, MADV_DONTNEED);
        }
#else
        (void)used;
#endif
        return p;
    }
    POOL_UNLOCK();
    *bytes = want;
    return map_fresh(want);
}

static void
pool_give_used(void *p, size_t bytes, size_t used)
{
    (void)used;
    if (p == NULL) {
        return;
    }
    if (bytes < POOL_HEAP_BYTES) {                /* pool_take's heap block */
        free(p);
        return;
    }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    int kept = 0;
#if defined(MADV_FREE)
    madvise(p, bytes, MADV_FREE);        /* before the mapping is in a slot, where another thread may take it */
#endif
    POOL_LOCK();
    if (bytes >= pool_floor && pool_kept + bytes <= POOL_MAX_BYTES) {
        for (int i = 0; i < POOL_SLOTS && !kept; i++) {
            if (pool_slot[i].p == NULL) {
                pool_slot[i].p = p;
                pool_slot[i].bytes = bytes;
                pool_slot[i].used = used < bytes ? used : bytes;
                pool_kept += bytes;
                kept = 1;
            }
        }
    }
    POOL_UNLOCK();
    if (kept) {
        return;
    }
#endif
    arena_free(p, bytes);
}

static void
pool_give(void *p, size_t bytes)
{
    pool_give_used(p, bytes, bytes);
}

/* At and above POOL_DROP_BYTES written, a user's scratch is given back with its pages dropped
 * (MADV_DONTNEED: the mapping is kept, its pages are not): the census's slots and the weld's entries of a
 * 10M-face file (114 and 236 MiB) would otherwise stay resident, lazily freed, into the stages after it and
 * set the analysis's peak (issue 25: 1.50x the file).  Below, a batch of smaller parts keeps reusing the
 * pages written, as before. */
#define POOL_DROP_BYTES ((size_t)32 << 20)

static void
pool_give_dropped(void *p, size_t bytes)
{
#if defined(__linux__) && defined(MADV_DONTNEED) && defined(MADV_HUGEPAGE)
    if (p != NULL && bytes >= POOL_DROP_BYTES) {
        madvise(p, bytes, MADV_DONTNEED);
        pool_give_used(p, bytes, 0);
        return;
    }
#endif
    pool_give(p, bytes);
}

/* arena_alloc: map_fresh for the kernels outside the weld and the census (the face-pair check), which first
 * unmaps the mappings kept for the next weld or census (pool_drain): kept pages never coexist with another
 * kernel's fresh ones, so keeping them never raises the process's peak above what unmapping them would. */
static void pool_drain(void);

static void *
arena_alloc(size_t bytes)
{
    pool_drain();
    return map_fresh(bytes);
}

static void
pool_drain(void)
{
    POOL_LOCK();
    for (int i = 0; i < POOL_SLOTS; i++) {
        arena_free(pool_slot[i].p, pool_slot[i].bytes);
        pool_slot[i].p = NULL;
        pool_slot[i].bytes = pool_slot[i].used = 0;
    }
    pool_kept = 0;
    POOL_UNLOCK();
}

static inline uint32_t
popcount64(uint64_t x)
{
    x = x - ((x >> 1) & 0x5555555555555555ULL);
    x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0FULL;
    return (uint32_t)((x * 0x0101010101010101ULL) >> 56);
}

static void
pw_release(PartWelderObject *w)
{
    for (size_t i = 0; i < w->n_chunks; i++) {
        free(w->chunks[i].off);
    }
    free(w->chunks);
    w->chunks = NULL;
    size_t used = w->entries_used * sizeof(PwEntry);
    pool_give_used(w->entries, w->arena_bytes, used > w->released ? used : 0);   /* released: the gather's */
    w->entries = NULL;
    w->arena_bytes = 0;
    if (w->has_index) {
        PyBuffer_Release(&w->index);
        w->has_index = 0;
    }
    w->n_chunks = w->chunks_cap = 0;
    for (int t = 0; t < MAX_THREADS; t++) {
        free(w->mark[t]);
        w->mark[t] = NULL;
    }
    free(w->recent);
    w->recent = NULL;
    pool_give(w->stage, w->stage_bytes);
    w->stage = NULL;
    w->stage_cap = w->stage_bytes = 0;
    free(w->nv);
    free(w->rank);
    w->nv = NULL;
    w->rank = NULL;
}

static inline void
pw_load(const char *p, Py_ssize_t sc, uint32_t *key)
{
    for (int c = 0; c < 3; c++) {
        memcpy(&key[c], p + c * sc, 4);
        if (key[c] == 0x80000000U) {
            key[c] = 0;
        }
    }
}

/* The feed's hash of a point: hash32's two multiplies, then one xor-shift and one multiply, whose top bits (the
 * bucket) and bits 40-53 (the recent-point slot) depend on every bit of the key.  Cheaper than hash32's full
 * finaliser, which finish keeps for its tables' slots (the low bits); any hash gives the same result (equal
 * points, equal hashes), only the balance of the buckets and the speed depend on it (feed 12.9 -> 11.2 ns per
 * corner of CPU on the 10M-face torus, same hit rate). */
static inline uint64_t
pw_hash(const uint32_t *k)
{
    uint64_t h = (((uint64_t)k[1] << 32) | k[0]) * 0x9E3779B97F4A7C15ULL;
    h ^= (uint64_t)k[2] * 0xC2B2AE3D27D4EB4FULL;
    return (h ^ (h >> 29)) * 0xff51afd7ed558ccdULL;
}

typedef struct {
    const char *base;
    Py_ssize_t n0, n1, s0, s1, sc;
    PwChunk *chunk;
    int bits;
    PwEntry *stage;                    /* the chunk's size: part t stages its misses from its first point's place */
    size_t staged[MAX_THREADS];        /* per part: its misses */
    Recent32 *recent[MAX_THREADS];
} PwFeedTask;

/* Part t of the chunk, first pass.  A point the part's recent-point cache holds (full key compared) refers to
 * that earlier corner (-1 - corner in the index); any other is counted in its bucket's histogram and staged,
 * with its corner, in order. */
static void
pw_stage_task(void *ctx, int t, int nt)
{
    PwFeedTask *f = (PwFeedTask *)ctx;
    PwChunk *c = f->chunk;
    size_t nb = (size_t)1 << f->bits, lo = part_start(c->size, t, nt), hi = part_start(c->size, t + 1, nt);
    int shift = 64 - f->bits;
    uint32_t *off = c->off + (size_t)t * (nb + 1);
    Recent32 *recent = f->recent[t];
    PwEntry *stage = f->stage + lo, *staged = stage;
    memset(off, 0, (nb + 1) * sizeof(uint32_t));
    memset(recent, 0, PW_RECENT * sizeof(Recent32));
    Py_ssize_t i0 = (Py_ssize_t)lo / f->n1, i1 = (Py_ssize_t)lo % f->n1;
    for (size_t k = lo; k < hi; k++) {
        uint32_t key[3];
        pw_load(f->base + i0 * f->s0 + i1 * f->s1, f->sc, key);
        if (++i1 == f->n1) { i1 = 0; i0++; }
        uint64_t h = pw_hash(key);
        Recent32 *r = recent + ((h >> 40) & (PW_RECENT - 1));
        if (r->id != 0 && r->k[0] == key[0] && r->k[1] == key[1] && r->k[2] == key[2]) {
            c->bucket[k] = -(int32_t)r->id;                 /* id = corner + 1 */
            continue;
        }
        int32_t b = f->bits ? (int32_t)(h >> shift) : 0;
        c->bucket[k] = b;
        off[b + 1]++;
        r->k[0] = staged->k[0] = key[0];
        r->k[1] = staged->k[1] = key[1];
        r->k[2] = staged->k[2] = key[2];
        staged->corner = c->corner0 + (uint32_t)k;
        staged++;
        r->id = c->corner0 + (uint32_t)k + 1;
    }
    f->staged[t] = (size_t)(staged - stage);
}

/* Part t of the chunk, second pass (after every part is staged): the part's staged points are copied into
 * the chunk's entries right after those of the parts before it (a stable scatter), so that the chunk's
 * entries are contiguous: until issue 25's sixth pass part t started at its first point's place, leaving a
 * gap of the hits between parts whose pages were written all the same (125 of the 361 MiB of entries of
 * the 10M-face torus).  The scatter reads the staged misses (16 bytes each, in order) rather than the part's
 * records again (50 bytes per three points, past the L2 cache by then) and skips the hits without a branch on
 * each point. */
static void
pw_scatter_task(void *ctx, int t, int nt)
{
    PwFeedTask *f = (PwFeedTask *)ctx;
    PwChunk *c = f->chunk;
    size_t nb = (size_t)1 << f->bits, lo = part_start(c->size, t, nt), start = 0;
    uint32_t *off = c->off + (size_t)t * (nb + 1);
    uint32_t cursor[(size_t)1 << PW_MAX_BITS];
    for (int s = 0; s < t; s++) {
        start += f->staged[s];
    }
    off[0] = (uint32_t)start;
    for (size_t b = 0; b < nb; b++) {
        off[b + 1] += off[b];
        cursor[b] = off[b];
    }
    const PwEntry *stage = f->stage + lo;
    for (const PwEntry *e = stage; e < stage + f->staged[t]; e++) {
        int32_t b = c->bucket[e->corner - c->corner0];
        c->entries[cursor[b]++] = *e;
    }
}

typedef struct {
    PartWelderObject *w;
    int32_t ticket;
    int nomem;
} PwTask;

/* Weld the buckets this thread draws: a table (load <= 1/2, doubled when full) of the entry numbers of the
 * bucket's distinct points so far, each compared in place with the point it names. */
static void
pw_weld_task(void *ctx, int t, int nt)
{
    PwTask *task = (PwTask *)ctx;
    PartWelderObject *w = task->w;
    size_t nb = (size_t)1 << w->bits;
    uint32_t *slots = NULL;
    size_t slots_cap = 0;
    uint64_t *mark = w->mark[t];
    PwEntry *entries = w->entries;         /* fewer than 2**31 - 1 entries: an entry number + 1 fits a slot */
    for (;;) {
        int32_t b = next_ticket(&task->ticket);
        if (b < 0 || (size_t)b >= nb || __atomic_load_n(&task->nomem, __ATOMIC_RELAXED)) {
            break;
        }
        size_t points = 0;
        for (size_t i = 0; i < w->n_chunks; i++) {
            const PwChunk *c = &w->chunks[i];
            for (int p = 0; p < c->nt; p++) {
                const uint32_t *off = c->off + (size_t)p * (nb + 1);
                points += off[b + 1] - off[b];
            }
        }
        /* a table for every point of the bucket at load <= 1/2 (a bucket holds at most as many vertices as
         * points: no growth); a bucket of more than 2**20 points (one point recurring past the recent-point
         * cache) starts at half its points and grows with its vertices */
        size_t cap = 64, want = points <= ((size_t)1 << 20) ? 2 * points : points / 2;
        while (cap < want) {
            cap *= 2;
        }
        if (cap > slots_cap) {
            free(slots);
            slots = (uint32_t *)malloc(cap * sizeof(uint32_t));
            slots_cap = slots ? cap : 0;
            if (slots == NULL) {
                __atomic_store_n(&task->nomem, 1, __ATOMIC_RELAXED);
                break;
            }
        }
        memset(slots, 0, cap * sizeof(uint32_t));
        size_t mask = cap - 1, count = 0;
        int failed = 0;
        for (size_t i = 0; i < w->n_chunks && !failed; i++) {
            const PwChunk *c = &w->chunks[i];
            for (int p = 0; p < c->nt && !failed; p++) {
                const uint32_t *off = c->off + (size_t)p * (nb + 1);
                for (PwEntry *e = c->entries + off[b], *end = c->entries + off[b + 1]; e < end; e++) {
                    size_t j = (size_t)hash32(e->k) & mask;
                    uint32_t id;
                    for (;;) {          /* the load stays <= 1/2: an empty slot exists */
                        id = slots[j];
                        if (id == 0) {
                            break;
                        }
                        const PwEntry *o = entries + (id - 1);
                        if (o->k[0] == e->k[0] && o->k[1] == e->k[1] && o->k[2] == e->k[2]) {
                            break;
                        }
                        j = (j + 1) & mask;
                    }
                    if (id != 0) {
                        e->corner = entries[id - 1].corner;   /* its vertex's first corner (the key stays:
                                                                * output writes the vertex from it) */
                        continue;
                    }
                    /* a new vertex: this point is its first corner (its entry keeps its own corner) */
                    mark[e->corner >> 6] |= (uint64_t)1 << (e->corner & 63);
                    slots[j] = (uint32_t)(e - entries) + 1;
                    if (2 * ++count > cap) {       /* double the table and re-insert the entry numbers */
                        size_t ncap = 2 * cap;
                        uint32_t *ns = (uint32_t *)calloc(ncap, sizeof(uint32_t));
                        if (ns == NULL) {
                            __atomic_store_n(&task->nomem, 1, __ATOMIC_RELAXED);
                            failed = 1;
                            break;
                        }
                        for (size_t q = 0; q < cap; q++) {
                            if (slots[q] == 0) {
                                continue;
                            }
                            size_t r = (size_t)hash32(entries[slots[q] - 1].k) & (ncap - 1);
                            while (ns[r] != 0) {
                                r = (r + 1) & (ncap - 1);
                            }
                            ns[r] = slots[q];
                        }
                        free(slots);
                        slots = ns;
                        cap = slots_cap = ncap;
                        mask = cap - 1;
                    }
                }
            }
        }
        if (failed) {
            break;
        }
        w->nv[b] = (uint32_t)count;
    }
    free(slots);
    (void)t;
    (void)nt;
}

typedef struct {
    PartWelderObject *w;
    double *vertices;
    int32_t *index;
    int32_t ticket;
    uint8_t *done;         /* per chunk: gathered (its entries are read no more) */
    size_t gathered;       /* chunks [0, gathered) all gathered */
    int lock;              /* held by the thread moving `gathered` and releasing pages */
} PwOutTask;

/* The entries' pages before chunk o->gathered (or, once all are gathered, all of them) given back to the
 * kernel (MADV_DONTNEED): the gather reads each chunk's entries once, in the chunks' order give or take a
 * thread, so the entries shrink while the vertices grow and the two never peak together (issue 25: the
 * entries and the vertices, 236 + 114 MiB on the 10M-face torus, had been resident together until the weld
 * returned, and the entries went on into the census's pages, kept).  Only entries of POOL_DROP_BYTES and
 * more (a mapping): a batch of smaller parts keeps reusing the pages written. */
static void
pw_release_gathered(PwOutTask *o)
{
#if defined(__linux__) && defined(MADV_DONTNEED) && defined(MADV_HUGEPAGE)
    PartWelderObject *w = o->w;
    if (w->entries_used * sizeof(PwEntry) < POOL_DROP_BYTES) {    /* smaller: kept for the next weld */
        return;
    }
    while (o->gathered < w->n_chunks && __atomic_load_n(&o->done[o->gathered], __ATOMIC_ACQUIRE)) {
        o->gathered++;
    }
    size_t upto = o->gathered < w->n_chunks ? (size_t)((char *)w->chunks[o->gathered].entries - (char *)w->entries)
                                            : w->arena_bytes;
    upto &= ~(size_t)4095;
    if (upto > w->released && (upto - w->released >= ((size_t)1 << 21) || o->gathered == w->n_chunks)) {
        madvise((char *)w->entries + w->released, upto - w->released, MADV_DONTNEED);
        w->released = upto;
    }
#else
    (void)o;
#endif
}

/* The corners of the chunks this thread draws, in file order, each through its bucket's cursor. */
static void
pw_gather_task(void *ctx, int t, int nt)
{
    PwOutTask *o = (PwOutTask *)ctx;
    PartWelderObject *w = o->w;
    size_t nb = (size_t)1 << w->bits;
    uint32_t cursor[(size_t)1 << PW_MAX_BITS];
    const uint64_t *mark = w->mark[0];
    for (;;) {
        int32_t u = next_ticket(&o->ticket);
        if (u < 0 || (size_t)u >= w->n_chunks) {
            break;
        }
        const PwChunk *c = &w->chunks[u];
        int32_t *out = o->index + c->corner0;
        for (int p = 0; p < c->nt; p++) {
            const uint32_t *off = c->off + (size_t)p * (nb + 1);
            memcpy(cursor, off, nb * sizeof(uint32_t));
            size_t lo = part_start(c->size, p, c->nt), hi = part_start(c->size, p + 1, c->nt);
            /* numbers by first appearance: each entry names its vertex's first corner; a corner that is its
             * own vertex's first is numbered `next`, the count of vertices first seen before it (marked corners
             * before the part's first, then counted along); any other takes the number of that first corner:
             * written already when it is in this part, else the marked corners before it (no pass over the
             * buckets to number them) */
            size_t c0 = c->corner0 + lo;
            uint32_t next = w->rank[c0 >> 6] + popcount64(mark[c0 >> 6] & (((uint64_t)1 << (c0 & 63)) - 1));
            for (size_t k = lo; k < hi; k++) {
                int32_t b = c->bucket[k];        /* the same memory as out[k] */
                if (b < 0) {
                    out[k] = o->index[-(int64_t)b - 1];    /* an earlier corner of this part: done */
                    continue;
                }
                const PwEntry *e = c->entries + cursor[b]++;
                uint32_t first = e->corner, g;
                if (first == c->corner0 + k) {   /* the vertex's first corner: its coordinates, in order */
                    double *v = o->vertices + 3 * (size_t)next;
                    for (int q = 0; q < 3; q++) {
                        float x;
                        memcpy(&x, &e->k[q], 4);
                        v[q] = (double)x;
                    }
                    g = next++;
                }
                else if (first >= c0) {          /* first seen earlier in this part: numbered already */
                    g = (uint32_t)out[first - c->corner0];
                }
                else {                           /* the marked corners before its first */
                    g = w->rank[first >> 6] + popcount64(mark[first >> 6] & (((uint64_t)1 << (first & 63)) - 1));
                }
                out[k] = (int32_t)g;
            }
        }
        __atomic_store_n(&o->done[u], 1, __ATOMIC_RELEASE);
        if (__atomic_exchange_n(&o->lock, 1, __ATOMIC_ACQUIRE) == 0) {   /* busy: its holder, or the caller
                                                                            after the threads, releases */
            pw_release_gathered(o);
            __atomic_store_n(&o->lock, 0, __ATOMIC_RELEASE);
        }
    }
    (void)t;
    (void)nt;
}

static int
PartWelder_init(PartWelderObject *w, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {"index", "threads", "bucket_bits", NULL};
    PyObject *index_obj;
    int threads = 1, bits = -1;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "O|ii", kwlist, &index_obj, &threads, &bits)) {
        return -1;
    }
    if (w->nv != NULL || w->state != 0 || w->points != 0) {
        PyErr_SetString(PyExc_RuntimeError, "PartWelder is already initialised");
        return -1;
    }
    if (bits > PW_MAX_BITS) {
        PyErr_Format(PyExc_ValueError, "Expected bucket_bits <= %d, got %d", PW_MAX_BITS, bits);
        return -1;
    }
    if (PyObject_GetBuffer(index_obj, &w->index, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        return -1;
    }
    w->has_index = 1;
    Py_ssize_t n_points = w->index.len / 4;
    if (signed_int_size(&w->index) != 4 || w->index.ndim != 1 || (size_t)n_points > MAX_VERTICES) {
        PyErr_SetString(PyExc_ValueError, "Expected `index` as a contiguous int32 array of fewer than 2**31 - 1 "
                        "entries");
        pw_release(w);
        return -1;
    }
    if (bits < 0) {
        bits = 0;
        while (bits < PW_MAX_BITS && ((size_t)PW_TARGET_POINTS << bits) < (size_t)n_points) {
            bits++;
        }
    }
    size_t nb = (size_t)1 << bits, words = ((size_t)n_points + 63) / 64 + 1;
    w->threads = thread_count(threads, (size_t)n_points, 1);
    w->bits = bits;
    w->n_points = (size_t)n_points;
    w->nv = (uint32_t *)calloc(nb, sizeof(uint32_t));
    w->rank = (uint32_t *)malloc(words * sizeof(uint32_t));
    int fits = (size_t)n_points <= (SIZE_MAX - 64) / sizeof(PwEntry);
    w->arena_bytes = fits ? (size_t)n_points * sizeof(PwEntry) + 64 : 0;
    w->entries = fits ? (PwEntry *)pool_take(&w->arena_bytes) : NULL;
    w->recent = (Recent32 *)malloc((size_t)w->threads * PW_RECENT * sizeof(Recent32));
    int ok = w->nv && w->rank && w->entries && w->recent;
    for (int t = 0; t < w->threads && ok; t++) {
        w->mark[t] = (uint64_t *)calloc(words, sizeof(uint64_t));
        ok = w->mark[t] != NULL;
    }
    if (!ok) {
        pw_release(w);
        PyErr_NoMemory();
        return -1;
    }
    return 0;
}

static void
PartWelder_dealloc(PartWelderObject *w)
{
    pw_release(w);
    Py_TYPE(w)->tp_free((PyObject *)w);
}

static int
pw_ready(PartWelderObject *w, int state)
{
    if (w->nv == NULL && w->state == 0) {
        PyErr_SetString(PyExc_RuntimeError, "PartWelder was not initialised");
        return -1;
    }
    if (w->busy) {
        PyErr_SetString(PyExc_RuntimeError, "PartWelder is in use by another thread");
        return -1;
    }
    if (w->state != state) {
        static const char *what[] = {"feeding", "finished", "written out"};
        PyErr_Format(PyExc_RuntimeError, "Expected a PartWelder %s, got one %s", what[state], what[w->state]);
        return -1;
    }
    return 0;
}

/* PartWelder.feed(points): partition (k, 3) or (k, j, 3) float32 points (any strides) into the buckets. */
static PyObject *
PartWelder_feed(PartWelderObject *w, PyObject *points_obj)
{
    if (pw_ready(w, 0) < 0) {
        return NULL;
    }
    Py_buffer pts;
    if (PyObject_GetBuffer(points_obj, &pts, PyBUF_STRIDES | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (native_code(pts.format) != 'f' || pts.itemsize != 4 || (pts.ndim != 2 && pts.ndim != 3)
            || pts.shape[pts.ndim - 1] != 3) {
        PyErr_Format(PyExc_ValueError, "Expected points as a (k, 3) or (k, j, 3) float32 array, got format %s "
                     "with %d dimensions", pts.format ? pts.format : "B", pts.ndim);
        PyBuffer_Release(&pts);
        return NULL;
    }
    Py_ssize_t n0 = pts.shape[0], n1 = pts.ndim == 3 ? pts.shape[1] : 1;
    if (n1 != 0 && n0 > PY_SSIZE_T_MAX / n1) {
        PyBuffer_Release(&pts);
        PyErr_SetString(PyExc_OverflowError, "too many points");
        return NULL;
    }
    size_t total = (size_t)(n0 * n1);
    if (total > w->n_points - w->points) {
        PyBuffer_Release(&pts);
        PyErr_Format(PyExc_ValueError, "Expected %zu points in all, got more", w->n_points);
        return NULL;
    }
    if (total == 0) {
        PyBuffer_Release(&pts);
        Py_RETURN_NONE;
    }
    if (w->n_chunks == w->chunks_cap) {
        size_t cap = w->chunks_cap ? 2 * w->chunks_cap : 16;
        PwChunk *chunks = (PwChunk *)realloc(w->chunks, cap * sizeof(PwChunk));
        if (chunks == NULL) {
            PyBuffer_Release(&pts);
            return PyErr_NoMemory();
        }
        w->chunks = chunks;
        w->chunks_cap = cap;
    }
    int nt = thread_count(w->threads, total, (size_t)1 << 14);
    size_t nb = (size_t)1 << w->bits;
    PwChunk *c = &w->chunks[w->n_chunks];
    c->entries = w->entries + w->entries_used;
    c->bucket = (int32_t *)w->index.buf + w->points;
    c->off = (uint32_t *)malloc((size_t)nt * (nb + 1) * sizeof(uint32_t));
    c->corner0 = (uint32_t)w->points;
    c->size = (uint32_t)total;
    c->nt = nt;
    if (c->off == NULL) {
        PyBuffer_Release(&pts);
        return PyErr_NoMemory();
    }
    if (total > w->stage_cap) {         /* the staging area: kept for the next chunk (the same size) */
        pool_give(w->stage, w->stage_bytes);
        w->stage_bytes = total * sizeof(PwEntry);
        w->stage = (PwEntry *)pool_take(&w->stage_bytes);
        w->stage_cap = w->stage ? total : 0;
        if (w->stage == NULL) {
            w->stage_bytes = 0;
            free(c->off);
            c->off = NULL;
            PyBuffer_Release(&pts);
            return PyErr_NoMemory();
        }
    }
    w->n_chunks++;
    PwFeedTask task = {(const char *)pts.buf, n0, n1, pts.strides[0], pts.ndim == 3 ? pts.strides[1] : 0,
                       pts.strides[pts.ndim - 1], c, w->bits, w->stage, {0}, {NULL}};
    for (int t = 0; t < nt; t++) {
        task.recent[t] = w->recent + (size_t)t * PW_RECENT;
    }
    w->busy = 1;
    Py_BEGIN_ALLOW_THREADS
    run_parallel(nt, pw_stage_task, &task);
    run_parallel(nt, pw_scatter_task, &task);
    Py_END_ALLOW_THREADS
    w->busy = 0;
    w->points += total;
    w->entries_used += c->off[(size_t)(nt - 1) * (nb + 1) + nb];   /* the end of the last part's entries */
    for (int t = 0; t < nt; t++) {
        w->partitioned += c->off[(size_t)t * (nb + 1) + nb] - c->off[(size_t)t * (nb + 1)];
    }
    PyBuffer_Release(&pts);
    Py_RETURN_NONE;
}

/* PartWelder.finish() -> count: weld every bucket; the number of distinct points. */
static PyObject *
PartWelder_finish(PartWelderObject *w, PyObject *unused)
{
    if (pw_ready(w, 0) < 0) {
        return NULL;
    }
    if (w->points != w->n_points) {
        PyErr_Format(PyExc_ValueError, "Expected %zu points, got %zu", w->n_points, (size_t)w->points);
        return NULL;
    }
    size_t words = (w->n_points + 63) / 64 + 1;
    PwTask task = {w, 0, 0};
    pool_give(w->stage, w->stage_bytes);        /* every chunk is fed */
    w->stage = NULL;
    w->stage_cap = w->stage_bytes = 0;
    int nt = thread_count(w->threads, w->n_points, (size_t)1 << 14);
    w->busy = 1;
    Py_BEGIN_ALLOW_THREADS
    run_parallel(nt, pw_weld_task, &task);
    if (!task.nomem) {
        uint64_t *mark = w->mark[0];
        uint32_t run = 0;
        for (size_t i = 0; i < words; i++) {
            uint64_t m = mark[i];
            for (int t = 1; t < w->threads; t++) {
                m |= w->mark[t][i];
            }
            mark[i] = m;
            w->rank[i] = run;
            run += popcount64(m);
        }
        for (int t = 1; t < w->threads; t++) {
            free(w->mark[t]);
            w->mark[t] = NULL;
        }
        w->count = run;
    }
    Py_END_ALLOW_THREADS
    w->busy = 0;
    if (task.nomem) {
        pw_release(w);
        w->state = 2;
        return PyErr_NoMemory();
    }
    w->state = 1;
    return PyLong_FromSize_t(w->count);
}

/* PartWelder.output(vertices): each point's vertex id into `index` (the array given to the constructor),
 * the distinct points into the contiguous float64 `vertices` (count, 3); then the welder's memory is freed. */
static PyObject *
PartWelder_output(PartWelderObject *w, PyObject *vert_obj)
{
    if (pw_ready(w, 1) < 0) {
        return NULL;
    }
    Py_buffer vert;
    if (PyObject_GetBuffer(vert_obj, &vert, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        return NULL;
    }
    if (native_code(vert.format) != 'd' || vert.itemsize != 8 || vert.len != (Py_ssize_t)(w->count * 3 * 8)) {
        PyErr_Format(PyExc_ValueError, "Expected `vertices` as a contiguous float64 array of shape (%zu, 3)",
                     w->count);
        goto fail;
    }
    PwOutTask task = {w, (double *)vert.buf, (int32_t *)w->index.buf, 0,
                      (uint8_t *)calloc(w->n_chunks ? w->n_chunks : 1, 1), 0, 0};
    if (task.done == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    int nt = thread_count(w->threads, w->n_points, (size_t)1 << 14);
    w->busy = 1;
    Py_BEGIN_ALLOW_THREADS
    run_parallel(nt, pw_gather_task, &task);
    pw_release_gathered(&task);         /* all gathered: the rest of the entries */
    Py_END_ALLOW_THREADS
    free(task.done);
    pw_release(w);                      /* releases the index buffer: with the GIL */
    w->busy = 0;
    w->state = 2;
    PyBuffer_Release(&vert);
    Py_RETURN_NONE;
fail:
    PyBuffer_Release(&vert);
    return NULL;
}

static PyObject *
PartWelder_get_count(PartWelderObject *w, void *closure)
{
    return PyLong_FromSize_t(w->state >= 1 ? w->count : 0);
}

static PyObject *
PartWelder_get_points(PartWelderObject *w, void *closure)
{
    return PyLong_FromSize_t(w->points);
}

static PyObject *
PartWelder_get_partitioned(PartWelderObject *w, void *closure)
{
    return PyLong_FromSize_t(w->partitioned);
}

static PyObject *
PartWelder_get_buckets(PartWelderObject *w, void *closure)
{
    return PyLong_FromLong(1L << w->bits);
}

static PyMethodDef PartWelder_methods[] = {
    {"feed", (PyCFunction)PartWelder_feed, METH_O,
     "feed(points)\n\nPartition (k, 3) or (k, j, 3) float32 points (any strides; -0.0 equals +0.0), the next "
     "k[*j] of the stream, into the buckets."},
    {"finish", (PyCFunction)PartWelder_finish, METH_NOARGS,
     "finish() -> count\n\nWeld every bucket once all n_points are fed; the number of distinct points."},
    {"output", (PyCFunction)PartWelder_output, METH_O,
     "output(vertices)\n\nWrite each point's vertex id (first-appearance order) into the constructor's `index` "
     "and the distinct points into the (count, 3) float64 array `vertices`; frees the welder's memory."},
    {NULL, NULL, 0, NULL}
};

static PyGetSetDef PartWelder_getset[] = {
    {"count", (getter)PartWelder_get_count, NULL, "Distinct points (after finish).", NULL},
    {"points", (getter)PartWelder_get_points, NULL, "Points fed so far.", NULL},
    {"buckets", (getter)PartWelder_get_buckets, NULL, "Buckets of the radix partition.", NULL},
    {"partitioned", (getter)PartWelder_get_partitioned, NULL,
     "Points copied into the buckets so far (the others were found in a recent-point cache).", NULL},
    {NULL, NULL, NULL, NULL, NULL}
};

static PyTypeObject PartWelderType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "inertia_tool._accel.PartWelder",
    .tp_doc = "PartWelder(index, threads=1, bucket_bits=-1)\n\nExact weld of a stream of len(index) float32 "
              "points by radix partition into buckets welded in cache-sized tables on `threads` threads: "
              "feed() every chunk, finish(), output(vertices); each point's vertex id lands in `index` (a "
              "contiguous int32 array, which holds bucket numbers until then).  The same result as Welder.",
    .tp_basicsize = sizeof(PartWelderObject),
    .tp_itemsize = 0,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)PartWelder_init,
    .tp_dealloc = (destructor)PartWelder_dealloc,
    .tp_methods = PartWelder_methods,
    .tp_getset = PartWelder_getset,
};

/* Scratch(nbytes): a writable buffer of nbytes taken from the kept mappings (pool_take), given back when the
 * object is freed (pool_give): the weld's output arrays (numpy.frombuffer over it), so that an analysis after
 * another in the same process writes its corner ids and vertices into pages faulted in already.  Its
 * contents start undefined, as numpy.empty's. */
typedef struct {
    PyObject_HEAD
    void *p;
    size_t bytes;          /* the mapping's size (pool_take may give a larger one) */
    Py_ssize_t len;        /* the buffer's */
} ScratchObject;

static PyObject *
Scratch_new(PyTypeObject *type, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {"nbytes", NULL};
    Py_ssize_t len;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "n", kwlist, &len)) {
        return NULL;
    }
    if (len < 0) {
        PyErr_Format(PyExc_ValueError, "Expected a number of bytes >= 0, got %zd", len);
        return NULL;
    }
    ScratchObject *b = (ScratchObject *)type->tp_alloc(type, 0);
    if (b == NULL) {
        return NULL;
    }
    b->bytes = len ? (size_t)len : 1;
    b->p = pool_take(&b->bytes);
    b->len = len;
    if (b->p == NULL) {
        b->bytes = 0;
        Py_DECREF(b);
        return PyErr_NoMemory();
    }
    return (PyObject *)b;
}

static void
Scratch_dealloc(ScratchObject *b)
{
    pool_give_used(b->p, b->bytes, (size_t)b->len);
    Py_TYPE(b)->tp_free((PyObject *)b);
}

static int
Scratch_getbuffer(ScratchObject *b, Py_buffer *view, int flags)
{
    return PyBuffer_FillInfo(view, (PyObject *)b, b->p, b->len, 0, flags);
}

static PyBufferProcs Scratch_as_buffer = {
    .bf_getbuffer = (getbufferproc)Scratch_getbuffer,
};

static PyTypeObject ScratchType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "inertia_tool._accel.Scratch",
    .tp_doc = "Scratch(nbytes)\n\nA writable buffer of nbytes (contents undefined) from the mappings the weld and "
              "the census keep; given back to them when freed.  numpy.frombuffer(Scratch(n), dtype) is an "
              "uninitialised array whose pages an earlier analysis in the process may have faulted in.",
    .tp_basicsize = sizeof(ScratchObject),
    .tp_itemsize = 0,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = Scratch_new,
    .tp_dealloc = (destructor)Scratch_dealloc,
    .tp_as_buffer = &Scratch_as_buffer,
};

/* ======================================================================================================
 * 3. edge_census
 *
 * Directed edges a->b (three per face) are bucketed by their start vertex a (a CSR adjacency, 3m int32
 * targets plus n+1 offsets) and each bucket is sorted.  An undirected edge {a, b} is used fwd times as a->b
 * (the run of b in a's bucket) and bwd times as b->a (found by binary search in b's bucket); it is counted
 * once, from its smaller end or from the only end that uses it.  Definitions as checks.edge_topology:
 * boundary = used once, non-manifold = more than twice, misoriented = twice in the same direction.
 *
 * Threads: thread t owns the start vertices of the t-th of nt equal ranges.  It scans all faces and counts,
 * then places, only the edges that start in its range, sorts its buckets, and (after all have finished)
 * takes the census of its range; the counts add and the samples merge, so the result is the serial one.
 * ====================================================================================================== */

#define SAMPLE 5
#define CENSUS_PARALLEL_MIN ((size_t)1 << 15)   /* faces below which one thread does everything */
#define CENSUS_MAX_THREADS 4    /* each thread scans every face twice: more threads cost more than they save */

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

typedef struct {
    uint64_t edges, boundary, nonmanifold, misoriented;
    SmallestKeys sb, sn, sm;
} CensusTally;

typedef struct {
    const void *f;
    int size;
    size_t m, n;
    int64_t *off;          /* n + 1: counts, then bucket starts, then (after placing) bucket ends */
    int32_t *tgt;
    CensusTally tally[MAX_THREADS];
} CensusTask;

static void
census_count_task(void *ctx, int t, int nt)
{
    CensusTask *c = (CensusTask *)ctx;
    int64_t lo = (int64_t)part_start(c->n, t, nt), hi = (int64_t)part_start(c->n, t + 1, nt);
    for (size_t i = 0; i < 3 * c->m; i++) {
        int64_t a = index_at(c->f, c->size, i);
        if (a >= lo && a < hi) {
            c->off[a]++;
        }
    }
}

static void
census_place_task(void *ctx, int t, int nt)
{
    CensusTask *c = (CensusTask *)ctx;
    int64_t lo = (int64_t)part_start(c->n, t, nt), hi = (int64_t)part_start(c->n, t + 1, nt);
    int64_t first = lo < hi ? c->off[lo] : 0;    /* off[lo - 1] belongs to the thread below: not read */
    for (size_t i = 0; i < c->m; i++) {
        for (int k = 0; k < 3; k++) {
            int64_t a = index_at(c->f, c->size, 3 * i + k);
            if (a >= lo && a < hi) {
                c->tgt[c->off[a]++] = (int32_t)index_at(c->f, c->size, 3 * i + (k + 1) % 3);
            }
        }
    }
    for (int64_t a = lo; a < hi; a++) {      /* off[a] is now the end of a's bucket */
        size_t start = a == lo ? (size_t)first : (size_t)c->off[a - 1];
        sort_bucket(c->tgt + start, (size_t)c->off[a] - start);
    }
}

static void
census_tally_task(void *ctx, int t, int nt)
{
    CensusTask *c = (CensusTask *)ctx;
    CensusTally *y = &c->tally[t];
    const int64_t *off = c->off;
    const int32_t *tgt = c->tgt;
    size_t n = c->n;
    memset(y, 0, sizeof(*y));
    for (size_t a = part_start(n, t, nt); a < part_start(n, t + 1, nt); a++) {
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
                y->edges++;
                if (total == 1) {
                    y->boundary++;
                    keep_smallest(&y->sb, key);
                }
                else if (total > 2) {
                    y->nonmanifold++;
                    keep_smallest(&y->sn, key);
                }
                else if (fwd == 2 || bwd == 2) {
                    y->misoriented++;
                    keep_smallest(&y->sm, key);
                }
            }
            p = q;
        }
    }
}

static void
merge_smallest(SmallestKeys *into, const SmallestKeys *from)
{
    for (int i = 0; i < from->count; i++) {
        keep_smallest(into, from->key[i]);
    }
}

static PyObject *
accel_edge_census(PyObject *self, PyObject *args)
{
    PyObject *faces_obj;
    Py_ssize_t n_vertices;
    int threads = 1;
    if (!PyArg_ParseTuple(args, "On|i", &faces_obj, &n_vertices, &threads) || check_vertex_count(n_vertices) < 0) {
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
    CensusTask *c = (CensusTask *)calloc(1, sizeof(CensusTask));
    int64_t *off = (int64_t *)calloc(n + 1, sizeof(int64_t));
    int32_t *tgt = directed > SIZE_MAX / sizeof(int32_t) ? NULL
                   : (int32_t *)malloc((directed ? directed : 1) * sizeof(int32_t));
    if (c == NULL || off == NULL || tgt == NULL) {
        free(c);
        free(off);
        free(tgt);
        PyBuffer_Release(&fv);
        return PyErr_NoMemory();
    }
    c->f = fv.buf;
    c->size = size;
    c->m = (size_t)m;
    c->n = n;
    c->off = off;
    c->tgt = tgt;
    int nt = thread_count(threads < CENSUS_MAX_THREADS ? threads : CENSUS_MAX_THREADS, (size_t)m,
                          CENSUS_PARALLEL_MIN);
    if ((size_t)nt > n) {
        nt = n ? (int)n : 1;
    }
    Py_BEGIN_ALLOW_THREADS
    run_parallel(nt, census_count_task, c);
    int64_t run = 0;
    for (size_t a = 0; a < n; a++) {
        int64_t d = off[a];
        off[a] = run;
        run += d;
    }
    run_parallel(nt, census_place_task, c);
    run_parallel(nt, census_tally_task, c);
    for (int t = 1; t < nt; t++) {
        CensusTally *y = &c->tally[t];
        c->tally[0].edges += y->edges;
        c->tally[0].boundary += y->boundary;
        c->tally[0].nonmanifold += y->nonmanifold;
        c->tally[0].misoriented += y->misoriented;
        merge_smallest(&c->tally[0].sb, &y->sb);
        merge_smallest(&c->tally[0].sn, &y->sn);
        merge_smallest(&c->tally[0].sm, &y->sm);
    }
    Py_END_ALLOW_THREADS
    free(off);
    free(tgt);
    PyBuffer_Release(&fv);
    CensusTally *y = &c->tally[0];
    uint64_t nn = n ? n : 1;
    PyObject *lb = keys_to_list(&y->sb, nn), *ln = keys_to_list(&y->sn, nn), *lm = keys_to_list(&y->sm, nn);
    PyObject *result = NULL;
    if (lb && ln && lm) {
        result = Py_BuildValue("(KKKKOOO)", (unsigned long long)y->edges, (unsigned long long)y->boundary,
                               (unsigned long long)y->nonmanifold, (unsigned long long)y->misoriented, lb, ln, lm);
    }
    free(c);
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
 *
 * One thread: a lock-free concurrent version (compare-and-swap links) gave the same labels but was no
 * faster on two cores (0.74-1.17x of one thread on 5M-10M faces); the pass is short next to the others.
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

/* ------------------------------------------------------------------------------------------------------
 * 4b. edge_shell_labels -- faces joined through shared undirected edges (checks._edge_shell_labels)
 *
 * Each face edge {a, b} is bucketed by its smaller end u = min(a, b) as the packed word (v << 32) | face,
 * v = max(a, b) (a CSR over vertices: 3m words plus n + 1 offsets); each bucket is sorted, so the faces
 * using one edge form a run, and consecutive faces of a run are united (union-find over faces, union by
 * smaller index, path halving: each root is its component's first face).  Faces are then labelled by
 * their root's rank in face order, i.e. components are numbered by their first face, as the numpy path.
 * ------------------------------------------------------------------------------------------------------ */

static void
sort_words(uint64_t *t, size_t len)
{
    for (size_t i = 1; i < len; i++) {
        uint64_t x = t[i];
        size_t j = i;
        while (j > 0 && t[j - 1] > x) {
            t[j] = t[j - 1];
            j--;
        }
        t[j] = x;
    }
}

static int
cmp_uint64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static inline void
unite_faces(int32_t *parent, int32_t a, int32_t b)
{
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a < b) {
        parent[b] = a;
    }
    else if (b < a) {
        parent[a] = b;
    }
}

static PyObject *
accel_edge_shell_labels(PyObject *self, PyObject *args)
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
    if ((size_t)m > (size_t)INT32_MAX - 1) {
        PyErr_Format(PyExc_ValueError, "Expected fewer than 2**31 - 1 faces, got %zd", m);
        goto fail;
    }
    if (check_indices(fv.buf, size, 3 * (size_t)m, n_vertices) < 0) {
        goto fail;
    }
    size_t n = (size_t)n_vertices, mm = (size_t)m;
    int64_t *off = (int64_t *)calloc(n + 1, sizeof(int64_t));
    uint64_t *word = (uint64_t *)malloc((mm ? 3 * mm : 1) * sizeof(uint64_t));
    int32_t *parent = (int32_t *)malloc((mm ? mm : 1) * sizeof(int32_t));
    if (off == NULL || word == NULL || parent == NULL) {
        free(off);
        free(word);
        free(parent);
        PyErr_NoMemory();
        goto fail;
    }
    int64_t count = 0;
    Py_BEGIN_ALLOW_THREADS
    const void *f = fv.buf;
    for (size_t i = 0; i < 3 * mm; i++) {
        size_t face = i / 3, k = i - 3 * face;
        int64_t a = index_at(f, size, i), b = index_at(f, size, 3 * face + (k + 1) % 3);
        off[(a < b ? a : b) + 1]++;
    }
    for (size_t u = 0; u < n; u++) {
        off[u + 1] += off[u];
    }
    for (size_t face = 0; face < mm; face++) {          /* off[u] runs from u's bucket start to its end */
        for (int k = 0; k < 3; k++) {
            int64_t a = index_at(f, size, 3 * face + k), b = index_at(f, size, 3 * face + (k + 1) % 3);
            int64_t u = a < b ? a : b, v = a < b ? b : a;
            word[off[u]++] = ((uint64_t)v << 32) | (uint64_t)face;
        }
    }
    for (size_t face = 0; face < mm; face++) {
        parent[face] = (int32_t)face;
    }
    for (size_t u = 0; u < n; u++) {                     /* off[u] is now the end of u's bucket */
        size_t lo = u ? (size_t)off[u - 1] : 0, hi = (size_t)off[u];
        if (hi - lo > 32) {
            qsort(word + lo, hi - lo, sizeof(uint64_t), cmp_uint64);
        }
        else {
            sort_words(word + lo, hi - lo);
        }
        for (size_t p = lo + 1; p < hi; p++) {
            if ((word[p] >> 32) == (word[p - 1] >> 32)) {
                unite_faces(parent, (int32_t)(word[p - 1] & 0xffffffffu), (int32_t)(word[p] & 0xffffffffu));
            }
        }
    }
    /* a root precedes every face of its component: it gets its rank first */
    for (size_t face = 0; face < mm; face++) {
        int32_t r = find_root(parent, (int32_t)face);
        int64_t label;
        if (r == (int32_t)face) {
            label = count++;
        }
        else {
            label = out_size == 8 ? ((int64_t *)out.buf)[r] : ((int32_t *)out.buf)[r];
        }
        if (out_size == 8) {
            ((int64_t *)out.buf)[face] = label;
        }
        else {
            ((int32_t *)out.buf)[face] = (int32_t)label;
        }
    }
    Py_END_ALLOW_THREADS
    free(off);
    free(word);
    free(parent);
    PyBuffer_Release(&fv);
    PyBuffer_Release(&out);
    return PyLong_FromLongLong((long long)count);
fail:
    PyBuffer_Release(&fv);
    PyBuffer_Release(&out);
    return NULL;
}

/* ------------------------------------------------------------------------------------------------------
 * 4c. census_shells -- the edge census and the shell labels from one sorted adjacency, on several threads
 *
 * Each face edge k of face i (a -> b, a = f[i][k], b = f[i][k + 1 mod 3]) is bucketed by its smaller end
 * u = min(a, b) as its slot number 3i + k (32 bits): a CSR over vertices.  Thread t owns the vertices of the
 * t-th of nt equal ranges: it scans every face, counting and then placing only the edges whose u is in its
 * range (no per-thread counts, no atomics).  Threads then take blocks of vertices by ticket; each bucket's
 * slots are expanded, in a small buffer of the thread's, into the words (v << 32) | (d << 31) | i,
 * v = max(a, b), d = [a > b] (the face read back through the slot), and sorted, so that the uses of one
 * undirected edge {u, v} form a run: its length is fwd + bwd and its d bits say the directions.  The run gives
 * the census (as section 3: boundary = used once, non-manifold = more than twice, misoriented = twice in one
 * direction; counts added and smallest keys merged over threads) and, when labels are asked for, the face
 * pairs to unite (consecutive faces of the run), united at once.
 *
 * Union-find over faces (union by smaller index, path halving, as 4b): the threads unite concurrently,
 * linking a root under a smaller one by compare-and-swap (one thread: plain unions).  Whatever the order of
 * the unions, every root ends as its component's first face, and components are numbered by first face, as
 * 4b (a bitmap of the roots and its running counts give each root's number).  Then, as checks.shell_labels
 * does with sections 4 and 4b: when no vertex is shared by two components (so that the components through
 * shared vertices, section 4, are these same ones), they are renumbered by their smallest vertex, which is
 * section 4's numbering.  The result is 3 and 4b (and 4 where it applies) bit for bit whatever the thread
 * count.
 *
 * Memory (issue 25's sixth pass): 12 bytes per face (the slots) and 4 per vertex (the offsets), plus a bit
 * per face and a few kB per thread; the parents live in the caller's label array (int32: in place; int64:
 * its first half, widened into labels in rounds from the top, each round's writes landing on parents read
 * in the rounds before), and so do the offsets when the labels are int64 and the vertices fewer than the
 * faces (its second half, read no more once the tally is done).  The vertex owners of the renumbering reuse the slots.  Until then the census
 * bucketed 8-byte words carrying the face and the far end (24 bytes per face), the parents apart (4) and
 * per-thread counts (4 per vertex per thread): 401 against 135 MiB above its input on the 10M-face torus.
 * The big arrays are given back to the pool with their pages dropped (pool_give_dropped) so that they do not
 * stay resident into the stages after.  The offsets are 32-bit: 3 * faces must stay below 2**32 (checks.py
 * falls back otherwise).
 * ------------------------------------------------------------------------------------------------------ */

#define CS_BLOCK 2048               /* vertices per ticket when tallying */
#define CS_PARALLEL_MIN ((size_t)1 << 15)   /* faces below which one thread does everything */
#define CS_AHEAD 16                 /* prefetch distance (slots) of the tally */

typedef struct {
    const void *f;
    int size;
    size_t m, n;
    int nt;
    int bad;                             /* a face index out of range: nothing is computed */
    int several;                         /* more than one shell: the labels' numbering must be checked */
    int shared;                          /* a vertex carries faces of two components */
    int nomem;                           /* a thread's word buffer could not grow */
    int32_t ticket;
    size_t fpart[MAX_THREADS + 1];       /* part t of the faces: [fpart[t], fpart[t + 1]), 64-aligned starts */
    uint32_t *off;                       /* n + 1: counts, then bucket starts, then (placed) bucket ends; in
                                            the second half of int64 labels when it fits there */
    uint32_t *slot;                      /* 3m: slot 3i + k of each edge, by bucket */
    int32_t *parent;                     /* m (in the caller's labels), or NULL for the census alone */
    uint64_t *rootbit;                   /* m bits: face i is a root */
    uint32_t *rootrank;                  /* per word of rootbit: roots before it */
    int32_t *owner[MAX_THREADS];         /* per thread and vertex: the component it saw there (-1: none) */
    void *out;                           /* labels: m of out_size bytes */
    int out_size;
    size_t lo, hi;                       /* the faces of the current widening round */
    int64_t roots[MAX_THREADS];          /* per part: its edges, later its roots */
    int32_t *rank;                       /* per component: its rank by smallest vertex */
    CensusTally tally[MAX_THREADS];
    size_t off_bytes, slot_bytes, owner_bytes;   /* the mappings' sizes (pool_take); 0: off in the labels,
                                                    the owners in the slots */
} CsTask;

static inline int64_t
label_at(const void *out, int size, size_t i)
{
    return size == 8 ? ((const int64_t *)out)[i] : (int64_t)((const int32_t *)out)[i];
}

/* Vertex range of thread t: the buckets it counts, places and (by its ticket blocks, any range) tallies. */
static void
cs_count_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    uint32_t *cnt = c->off;
    uint64_t n = c->n, lo = part_start(c->n, t, nt), hi = part_start(c->n, t + 1, nt);
    if (hi > lo) {
        memset(cnt + lo, 0, (hi - lo) * sizeof(uint32_t));     /* a kept mapping holds old counts */
    }
    for (size_t i = 0; i < c->m; i++) {
        int64_t a = index_at(c->f, c->size, 3 * i), b = index_at(c->f, c->size, 3 * i + 1);
        int64_t d = index_at(c->f, c->size, 3 * i + 2);
        if ((uint64_t)a >= n || (uint64_t)b >= n || (uint64_t)d >= n) {   /* the caller reports where */
            __atomic_store_n(&c->bad, 1, __ATOMIC_RELAXED);
            return;
        }
        uint64_t u0 = (uint64_t)(a < b ? a : b) - lo, u1 = (uint64_t)(b < d ? b : d) - lo;
        uint64_t u2 = (uint64_t)(d < a ? d : a) - lo;
        if (u0 < hi - lo) cnt[lo + u0]++;                      /* unsigned: below lo wraps past hi - lo */
        if (u1 < hi - lo) cnt[lo + u1]++;
        if (u2 < hi - lo) cnt[lo + u2]++;
    }
}

/* Bucket starts for the vertices of part t: first the sums of each part, then the starts. */
static void
cs_sum_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    uint64_t sum = 0;
    for (size_t u = part_start(c->n, t, nt); u < part_start(c->n, t + 1, nt); u++) {
        sum += c->off[u];
    }
    c->roots[t] = (int64_t)sum;
}

static void
cs_start_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    uint32_t run = (uint32_t)c->roots[t];      /* the edges of the vertices before the part */
    for (size_t u = part_start(c->n, t, nt); u < part_start(c->n, t + 1, nt); u++) {
        uint32_t k = c->off[u];
        c->off[u] = run;
        run += k;
    }
}

/* Thread t places the edges whose smaller end is in its vertex range; off[u] ends as the end of u's bucket. */
static void
cs_place_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    uint32_t *cursor = c->off, *slot = c->slot;
    uint64_t lo = part_start(c->n, t, nt), width = part_start(c->n, t + 1, nt) - lo;
    for (size_t i = 0; i < c->m; i++) {
        int64_t x0 = index_at(c->f, c->size, 3 * i), x1 = index_at(c->f, c->size, 3 * i + 1);
        int64_t x2 = index_at(c->f, c->size, 3 * i + 2);
        uint64_t u0 = (uint64_t)(x0 < x1 ? x0 : x1) - lo, u1 = (uint64_t)(x1 < x2 ? x1 : x2) - lo;
        uint64_t u2 = (uint64_t)(x2 < x0 ? x2 : x0) - lo;
        uint32_t s = (uint32_t)(3 * i);
        if (u0 < width) slot[cursor[lo + u0]++] = s;
        if (u1 < width) slot[cursor[lo + u1]++] = s + 1;
        if (u2 < width) slot[cursor[lo + u2]++] = s + 2;
    }
}

/* The root of x when other threads link and halve concurrently (relaxed atomic loads and stores: a parent only
 * ever moves to an ancestor, and every ancestor of a face is a smaller face, so no path ever cycles), with path
 * halving. */
static inline int32_t
cs_find(int32_t *parent, int32_t x)
{
    for (;;) {
        int32_t p = __atomic_load_n(&parent[x], __ATOMIC_RELAXED);
        if (p == x) {
            return x;
        }
        int32_t g = __atomic_load_n(&parent[p], __ATOMIC_RELAXED);
        if (g != p) {
            __atomic_store_n(&parent[x], g, __ATOMIC_RELAXED);   /* x is no root: only halving writes it */
        }
        x = g;
    }
}

/* Link the roots of faces a and b, the larger under the smaller (one thread: plain unite_faces). */
static inline void
cs_unite(int32_t *parent, int32_t a, int32_t b, int nt)
{
    if (nt == 1) {
        unite_faces(parent, a, b);
        return;
    }
    for (;;) {
        a = cs_find(parent, a);
        b = cs_find(parent, b);
        if (a == b) {
            return;
        }
        if (a > b) {
            int32_t x = a;
            a = b;
            b = x;
        }
        int32_t expected = b;      /* b is a root unless another thread has just linked it */
        if (__atomic_compare_exchange_n(&parent[b], &expected, a, 0, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
            return;
        }
    }
}

/* The vertex blocks this thread draws: each bucket's slots expanded into words and sorted, the census of its
 * runs taken and the consecutive faces of each run united. */
static void
cs_tally_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    CensusTally *y = &c->tally[t];
    const uint32_t *off = c->off, *slot = c->slot;
    uint64_t n = c->n;
    uint64_t local[64], *word = local;
    size_t cap = 64;
    memset(y, 0, sizeof(*y));
    for (;;) {
        int32_t blk = next_ticket(&c->ticket);
        if (blk < 0 || (size_t)blk * CS_BLOCK >= c->n || __atomic_load_n(&c->nomem, __ATOMIC_RELAXED)) {
            break;
        }
        size_t u0 = (size_t)blk * CS_BLOCK, u1 = u0 + CS_BLOCK < c->n ? u0 + CS_BLOCK : c->n;
        size_t last = off[u1 - 1];               /* the block's slots end here (bucket ends, after placing) */
        for (size_t u = u0; u < u1; u++) {
            size_t lo = u ? off[u - 1] : 0, hi = off[u], len = hi - lo;
            if (len > cap) {
                size_t ncap = cap;
                while (ncap < len) {
                    ncap *= 2;
                }
                uint64_t *grown = (uint64_t *)malloc(ncap * sizeof(uint64_t));
                if (grown == NULL) {
                    __atomic_store_n(&c->nomem, 1, __ATOMIC_RELAXED);
                    break;
                }
                if (word != local) {
                    free(word);
                }
                word = grown;
                cap = ncap;
            }
            for (size_t p = lo; p < hi; p++) {
                if (p + CS_AHEAD < last) {
                    uint32_t ahead = slot[p + CS_AHEAD];
                    __builtin_prefetch(c->size == 8 ? (const void *)((const int64_t *)c->f + ahead)
                                                    : (const void *)((const int32_t *)c->f + ahead));
                }
                uint32_t s = slot[p];
                uint32_t i = s / 3, k = s - 3 * i;
                int64_t a = index_at(c->f, c->size, s), b = index_at(c->f, c->size, 3 * (size_t)i + (k == 2 ? 0 : k + 1));
                uint64_t v = (uint64_t)(a < b ? b : a);
                word[p - lo] = (v << 32) | ((uint64_t)(a > b) << 31) | (uint64_t)i;
            }
            if (len > 32) {
                qsort(word, len, sizeof(uint64_t), cmp_uint64);
            }
            else {
                sort_words(word, len);
            }
            size_t p = 0;
            while (p < len) {
                uint64_t v = word[p] >> 32;
                size_t q = p + 1, backward = (word[p] >> 31) & 1;
                while (q < len && (word[q] >> 32) == v) {
                    backward += (word[q] >> 31) & 1;
                    q++;
                }
                size_t total = q - p;
                uint64_t key = (uint64_t)u * n + v;
                y->edges++;
                if (total == 1) {
                    y->boundary++;
                    keep_smallest(&y->sb, key);
                }
                else if (total > 2) {
                    y->nonmanifold++;
                    keep_smallest(&y->sn, key);
                }
                else if (backward != 1) {
                    y->misoriented++;
                    keep_smallest(&y->sm, key);
                }
                if (c->parent != NULL) {
                    int32_t g = (int32_t)(word[p] & 0x7fffffffu);
                    for (size_t r = p + 1; r < q; r++) {
                        int32_t h = (int32_t)(word[r] & 0x7fffffffu);
                        if (g != h) {
                            cs_unite(c->parent, g, h, nt);
                        }
                        g = h;
                    }
                }
                p = q;
            }
        }
    }
    if (word != local) {
        free(word);
    }
}

/* Part t of the faces: parents reset (before any thread unites). */
static void
cs_reset_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    for (size_t i = c->fpart[t]; i < c->fpart[t + 1]; i++) {
        c->parent[i] = (int32_t)i;
    }
    (void)nt;
}

/* Part t (64-aligned, so that its root bits are its own words): every face's parent set to its root (the
 * parents of other parts are read meanwhile: relaxed atomic loads and stores, each value an ancestor of the
 * face), roots marked and counted. */
static void
cs_root_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    int32_t *parent = c->parent;
    int64_t roots = 0;
    for (size_t i = c->fpart[t]; i < c->fpart[t + 1]; i++) {
        int32_t r = (int32_t)i, up;
        while ((up = __atomic_load_n(&parent[r], __ATOMIC_RELAXED)) != r) {
            r = up;
        }
        if (r == (int32_t)i) {
            roots++;
            c->rootbit[i >> 6] |= (uint64_t)1 << (i & 63);
        }
        else {
            __atomic_store_n(&parent[i], r, __ATOMIC_RELAXED);
        }
    }
    c->roots[t] = roots;
    (void)nt;
}

/* Number of roots before face r: the component number of a root r (components numbered by first face). */
static inline int64_t
cs_root_number(const CsTask *c, int32_t r)
{
    size_t w = (size_t)r >> 6;
    return (int64_t)c->rootrank[w] + popcount64(c->rootbit[w] & (((uint64_t)1 << (r & 63)) - 1));
}

/* int32 labels (the parents in place): part t of the faces, each parent replaced by its root's number. */
static void
cs_label32_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    int32_t *out = (int32_t *)c->out;
    for (size_t i = c->fpart[t]; i < c->fpart[t + 1]; i++) {
        out[i] = (int32_t)cs_root_number(c, out[i]);
    }
    (void)nt;
}

/* int64 labels over int32 parents in the array's first half: the faces [lo, hi) of this round, split over the
 * threads.  The label of face i overwrites parents 2i and 2i + 1, at least hi (lo >= hi / 2): faces of the
 * rounds before, done. */
static void
cs_label64_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    int64_t *out = (int64_t *)c->out;
    const int32_t *parent = c->parent;
    size_t a = c->lo + part_start(c->hi - c->lo, t, nt), b = c->lo + part_start(c->hi - c->lo, t + 1, nt);
    for (size_t i = b; i-- > a;) {
        int32_t r = parent[i];
        out[i] = cs_root_number(c, r);
    }
}

/* Part t: each vertex of the part's faces notes its component (owner[t], -1 when none); a vertex seen in two
 * components is flagged. */
static void
cs_owner_scan_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    int32_t *owner = c->owner[t];
    int shared = 0;
    memset(owner, 0xff, c->n * sizeof(int32_t));
    for (size_t i = c->fpart[t]; i < c->fpart[t + 1] && !shared; i++) {
        int32_t label = (int32_t)label_at(c->out, c->out_size, i);
        for (int k = 0; k < 3; k++) {
            int64_t v = index_at(c->f, c->size, 3 * i + k);
            if (owner[v] < 0) {
                owner[v] = label;
            }
            else if (owner[v] != label) {
                shared = 1;
            }
        }
    }
    if (shared) {
        __atomic_store_n(&c->shared, 1, __ATOMIC_RELAXED);
    }
    (void)nt;
}

/* Vertices of part t: the components the threads saw at each must agree; the agreed one into owner[0]. */
static void
cs_owner_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    int32_t *merged = c->owner[0];
    int shared = 0;
    for (size_t v = part_start(c->n, t, nt); v < part_start(c->n, t + 1, nt) && !shared; v++) {
        int32_t o = merged[v];
        for (int s = 1; s < c->nt; s++) {
            int32_t x = c->owner[s][v];
            if (x >= 0) {
                if (o < 0) {
                    o = x;
                }
                else if (o != x) {
                    shared = 1;
                }
            }
        }
        merged[v] = o;
    }
    if (shared) {
        __atomic_store_n(&c->shared, 1, __ATOMIC_RELAXED);
    }
}

/* Part t of the faces: labels replaced by their component's rank by smallest vertex. */
static void
cs_rank_task(void *ctx, int t, int nt)
{
    CsTask *c = (CsTask *)ctx;
    for (size_t i = c->fpart[t]; i < c->fpart[t + 1]; i++) {
        if (c->out_size == 8) {
            ((int64_t *)c->out)[i] = c->rank[((int64_t *)c->out)[i]];
        }
        else {
            ((int32_t *)c->out)[i] = c->rank[((int32_t *)c->out)[i]];
        }
    }
    (void)nt;
}

static void
cs_free(CsTask *c)
{
    if (c->off_bytes) {                  /* 0: in the caller's labels */
        pool_give_dropped(c->off, c->off_bytes);
    }
    pool_give_dropped(c->slot, c->slot_bytes);
    if (c->owner_bytes) {
        pool_give_dropped(c->owner[0], c->owner_bytes);
    }
    free(c->rootbit);
    free(c->rootrank);
    free(c->rank);
    free(c);
}

/* The census_shells work with the GIL released; -1 when memory ran out, -2 on an index out of range, else
 * the number of shells (0 when no labels were asked for). */
static int64_t
cs_run(CsTask *c)
{
    int nt = c->nt;
    run_parallel(nt, cs_count_task, c);       /* checks the indices too */
    if (c->bad) {
        return -2;
    }
    run_parallel(nt, cs_sum_task, c);
    int64_t run = 0;
    for (int t = 0; t < nt; t++) {
        int64_t s = c->roots[t];
        c->roots[t] = run;
        run += s;
    }
    c->off[c->n] = (uint32_t)run;
    run_parallel(nt, cs_start_task, c);
    run_parallel(nt, cs_place_task, c);
    if (c->parent != NULL) {
        run_parallel(nt, cs_reset_task, c);
    }
    c->ticket = 0;
    run_parallel(nt, cs_tally_task, c);
    if (c->nomem) {
        return -1;
    }
    for (int t = 1; t < nt; t++) {
        CensusTally *y = &c->tally[t];
        c->tally[0].edges += y->edges;
        c->tally[0].boundary += y->boundary;
        c->tally[0].nonmanifold += y->nonmanifold;
        c->tally[0].misoriented += y->misoriented;
        merge_smallest(&c->tally[0].sb, &y->sb);
        merge_smallest(&c->tally[0].sn, &y->sn);
        merge_smallest(&c->tally[0].sm, &y->sm);
    }
    if (c->parent == NULL) {
        return 0;
    }
    size_t words = c->m / 64 + 1;
    c->rootbit = (uint64_t *)calloc(words, sizeof(uint64_t));
    c->rootrank = (uint32_t *)malloc(words * sizeof(uint32_t));
    if (c->rootbit == NULL || c->rootrank == NULL) {
        return -1;
    }
    run_parallel(nt, cs_root_task, c);
    int64_t count = 0;
    for (int t = 0; t < nt; t++) {
        count += c->roots[t];
    }
    uint32_t before = 0;
    for (size_t w = 0; w < words; w++) {
        c->rootrank[w] = before;
        before += popcount64(c->rootbit[w]);
    }
    if (c->out_size == 4) {
        run_parallel(nt, cs_label32_task, c);
    }
    else {
        size_t hi = c->m;
        while (hi > 0) {                      /* rounds [lo, hi), lo = ceil(hi / 2); the last: [0, 1) */
            size_t lo = hi > 1 ? (hi + 1) / 2 : 0;
            c->lo = lo;
            c->hi = hi;
            run_parallel(hi - lo >= CS_PARALLEL_MIN ? nt : 1, cs_label64_task, c);
            hi = lo;
        }
    }
    c->several = count > 1;              /* one shell: numbered 0 by first face and by smallest vertex alike */
    if (!c->several) {
        return count;
    }
    /* the vertex owners: in the slots (done with) when they fit, else a mapping of their own */
    size_t need = (size_t)nt * (c->n ? c->n : 1) * sizeof(int32_t);
    int32_t *owners = (int32_t *)c->slot;
    if (need > c->slot_bytes) {
        c->owner_bytes = need;
        owners = (int32_t *)pool_take(&c->owner_bytes);
        if (owners == NULL) {
            c->owner_bytes = 0;
            return -1;
        }
    }
    for (int t = 0; t < nt; t++) {
        c->owner[t] = owners + (size_t)t * (c->n ? c->n : 1);
    }
    run_parallel(nt, cs_owner_scan_task, c);
    if (!c->shared) {
        run_parallel(nt, cs_owner_task, c);
    }
    if (!c->shared) {                    /* renumber by smallest vertex: components in order of first owner */
        c->rank = (int32_t *)malloc((size_t)count * sizeof(int32_t));
        if (c->rank == NULL) {
            return -1;
        }
        memset(c->rank, 0xff, (size_t)count * sizeof(int32_t));
        const int32_t *owner = c->owner[0];
        int32_t next = 0;
        for (size_t v = 0; v < c->n; v++) {
            int32_t o = owner[v];
            if (o >= 0 && c->rank[o] < 0) {
                c->rank[o] = next++;
            }
        }
        run_parallel(nt, cs_rank_task, c);
    }
    return count;
}

static PyObject *
accel_census_shells(PyObject *self, PyObject *args)
{
    PyObject *faces_obj, *out_obj;
    Py_ssize_t n_vertices;
    int threads = 1;
    Py_ssize_t parallel_min = (Py_ssize_t)CS_PARALLEL_MIN;
    if (!PyArg_ParseTuple(args, "OnO|in", &faces_obj, &n_vertices, &out_obj, &threads, &parallel_min)
            || check_vertex_count(n_vertices) < 0) {
        return NULL;
    }
    Py_buffer fv, out;
    Py_ssize_t m;
    int size, has_out = out_obj != Py_None;
    if (get_faces(faces_obj, &fv, &m, &size) < 0) {
        return NULL;
    }
    if (has_out && PyObject_GetBuffer(out_obj, &out, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyBuffer_Release(&fv);
        return NULL;
    }
    PyObject *result = NULL;
    CsTask *c = NULL;
    int out_size = has_out ? signed_int_size(&out) : 0;
    if (has_out && (out_size == 0 || out.ndim != 1 || out.shape[0] != m)) {
        PyErr_Format(PyExc_ValueError, "Expected `out` as a contiguous int32 or int64 array of %zd entries, or "
                     "None", m);
        goto done;
    }
    if ((size_t)m > (size_t)INT32_MAX - 1 || 3 * (uint64_t)m > (uint64_t)UINT32_MAX) {
        PyErr_Format(PyExc_ValueError, "Expected at most 1,431,655,765 faces, got %zd", m);
        goto done;
    }
    size_t n = (size_t)n_vertices, mm = (size_t)m;
    int nt = thread_count(threads, mm, parallel_min > 0 ? (size_t)parallel_min : 1);
    if ((size_t)nt > mm) {
        nt = mm ? (int)mm : 1;
    }
    c = (CsTask *)calloc(1, sizeof(CsTask));
    if (c == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    c->f = fv.buf;
    c->size = size;
    c->m = mm;
    c->n = n;
    c->nt = nt;
    c->out = has_out ? out.buf : NULL;
    c->out_size = out_size;
    c->parent = has_out ? (int32_t *)out.buf : NULL;     /* int64 labels: their first half until widened */
    for (int t = 0; t <= nt; t++) {
        c->fpart[t] = t == nt ? mm : part_start(mm, t, nt) & ~(size_t)63;   /* root bits: whole words */
    }
    c->slot_bytes = (mm ? 3 * mm : 1) * sizeof(uint32_t);
    if (has_out && out_size == 8 && n + 1 <= mm) {
        c->off = (uint32_t *)((char *)out.buf + 4 * mm);    /* the labels' second half, free until widened */
    }
    else {
        c->off_bytes = (n + 1) * sizeof(uint32_t);
        c->off = (uint32_t *)pool_take(&c->off_bytes);
    }
    c->slot = (uint32_t *)pool_take(&c->slot_bytes);
    if (c->off == NULL || c->slot == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    int64_t count;
    Py_BEGIN_ALLOW_THREADS
    count = cs_run(c);
    Py_END_ALLOW_THREADS
    if (count == -2) {
        check_indices(fv.buf, size, 3 * (size_t)m, n_vertices);    /* sets the error: where, which index */
        goto done;
    }
    if (count < 0) {
        PyErr_NoMemory();
        goto done;
    }
    CensusTally *y = &c->tally[0];
    uint64_t nn = n ? n : 1;
    PyObject *lb = keys_to_list(&y->sb, nn), *ln = keys_to_list(&y->sn, nn), *lm = keys_to_list(&y->sm, nn);
    if (lb && ln && lm) {
        result = Py_BuildValue("(KKKKOOOL)", (unsigned long long)y->edges, (unsigned long long)y->boundary,
                               (unsigned long long)y->nonmanifold, (unsigned long long)y->misoriented, lb, ln, lm,
                               (long long)(has_out ? count : -1));
    }
    Py_XDECREF(lb);
    Py_XDECREF(ln);
    Py_XDECREF(lm);
done:
    if (c != NULL) {
        cs_free(c);
    }
    PyBuffer_Release(&fv);
    if (has_out) {
        PyBuffer_Release(&out);
    }
    return result;
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
 *
 * Threads: large meshes are cut into SUM_LANES contiguous ranges of faces (a fixed number, not the thread
 * count), each summed into its own compensated accumulators by whichever thread is free next; the lanes
 * are then added in lane order.  The result depends on the face count only, never on the threads.
 * ====================================================================================================== */

#define NSUMS 11
#define SUM_LANES 32
#define SUM_LANES_MIN ((size_t)1 << 16)          /* faces below which one lane sums everything */
#define SUM_LANES_MAX_LABELS ((Py_ssize_t)1024)  /* labels above which one lane (bounded scratch memory) */

static inline void
two_sum_add(double *acc, double x)
{
    double s = acc[0] + x;
    double bp = s - acc[0];
    acc[1] += (acc[0] - (s - bp)) + (x - bp);
    acc[0] = s;
}

typedef struct {
    const double *v;
    const void *f, *lab;
    int size, label_size;
    size_t m;
    int lanes;
    Py_ssize_t n_labels;
    double ox, oy, oz, half_floor;
    double *acc;           /* lanes x n_labels x 2 NSUMS */
    int64_t *zero;         /* lanes x n_labels */
    Py_ssize_t bad[SUM_LANES];   /* first face with a label out of range in each lane, or -1 */
    int32_t next_lane;     /* the next lane to sum (next_ticket) */
} SumTask;

static void
sum_lane(SumTask *st, int lane)
{
    size_t lo = part_start(st->m, lane, st->lanes), hi = part_start(st->m, lane + 1, st->lanes);
    double *acc = st->acc + (size_t)lane * (size_t)st->n_labels * 2 * NSUMS;
    int64_t *zero = st->zero + (size_t)lane * (size_t)st->n_labels;
    const double *v = st->v;
    const void *f = st->f;
    int size = st->size;
    double ox = st->ox, oy = st->oy, oz = st->oz;
    st->bad[lane] = -1;
    for (size_t i = lo; i < hi; i++) {
        int64_t l = 0;
        if (st->lab != NULL) {
            l = index_at(st->lab, st->label_size, i);
            if (l < 0 || l >= st->n_labels) {
                st->bad[lane] = (Py_ssize_t)i;
                return;
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
        if (area <= st->half_floor) {
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
}

static void
sum_task(void *ctx, int t, int nt)
{
    SumTask *st = (SumTask *)ctx;
    for (int lane = next_ticket(&st->next_lane); lane < st->lanes; lane = next_ticket(&st->next_lane)) {
        sum_lane(st, lane);
    }
}

static PyObject *
accel_tetra_sums(PyObject *self, PyObject *args)
{
    PyObject *vert_obj, *faces_obj, *labels_obj, *sums_obj, *zero_obj;
    double ox, oy, oz, area_floor;
    int threads = 1;
    if (!PyArg_ParseTuple(args, "OO(ddd)dOOO|i", &vert_obj, &faces_obj, &ox, &oy, &oz, &area_floor, &labels_obj,
                          &sums_obj, &zero_obj, &threads)) {
        return NULL;
    }
    Py_buffer vv, fv, lv, sv, zv;
    double *acc = NULL;
    int64_t *zero_lanes = NULL;
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
    int lanes = ((size_t)m >= SUM_LANES_MIN && n_labels <= SUM_LANES_MAX_LABELS) ? SUM_LANES : 1;
    if (n_labels > PY_SSIZE_T_MAX / (Py_ssize_t)(2 * NSUMS * SUM_LANES * sizeof(double))) {
        PyErr_NoMemory();
        goto fail;
    }
    acc = (double *)calloc((size_t)lanes * (size_t)n_labels * 2 * NSUMS, sizeof(double));
    zero_lanes = (int64_t *)calloc((size_t)lanes * (size_t)n_labels, sizeof(int64_t));
    if (acc == NULL || zero_lanes == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    SumTask st = {(const double *)vv.buf, fv.buf, have_labels ? lv.buf : NULL, size, label_size, (size_t)m,
                  lanes, n_labels, ox, oy, oz, 0.5 * area_floor, acc, zero_lanes, {0}, 0};
    int nt = thread_count(threads, (size_t)m, SUM_LANES_MIN);
    Py_BEGIN_ALLOW_THREADS
    run_parallel(nt > lanes ? lanes : nt, sum_task, &st);
    for (int lane = 1; lane < lanes; lane++) {      /* lane order: independent of the thread count */
        const double *x = acc + (size_t)lane * (size_t)n_labels * 2 * NSUMS;
        for (size_t k = 0; k < (size_t)n_labels * NSUMS; k++) {
            two_sum_add(acc + 2 * k, x[2 * k]);
            acc[2 * k + 1] += x[2 * k + 1];
        }
        for (Py_ssize_t l = 0; l < n_labels; l++) {
            zero_lanes[l] += zero_lanes[(size_t)lane * (size_t)n_labels + (size_t)l];
        }
    }
    Py_END_ALLOW_THREADS
    for (int lane = 0; lane < lanes; lane++) {
        if (st.bad[lane] >= 0) {
            Py_ssize_t bad = st.bad[lane];
            PyErr_Format(PyExc_ValueError, "Expected labels in 0..%zd, got %lld at position %zd", n_labels - 1,
                         (long long)index_at(lv.buf, label_size, (size_t)bad), bad);
            goto fail;
        }
    }
    double *sums = (double *)sv.buf;
    for (Py_ssize_t k = 0; k < n_labels * NSUMS; k++) {
        sums[k] = acc[2 * k] + acc[2 * k + 1];
    }
    memcpy(zv.buf, zero_lanes, (size_t)n_labels * sizeof(int64_t));
    result = Py_None;
    Py_INCREF(result);
fail:
    free(acc);
    free(zero_lanes);
    PyBuffer_Release(&vv);
    PyBuffer_Release(&fv);
    PyBuffer_Release(&sv);
    PyBuffer_Release(&zv);
    if (have_labels) {
        PyBuffer_Release(&lv);
    }
    return result;
}

/* roundoff_sums: the per-face sums of integrals.roundoff_bounds, bit for bit those of its numpy loop (the
 * reference): with a, b, c the corners less `origin`, e1 = |b - a|, e2 = |c - a| and |.| taken entry by entry,
 *   P = 8 |a|.(e1 (x) e2) + 2 (|a|.((|a| + |b|) (x) e2) + |a|.(e1 (x) (|a| + |c|)))
 *   (x (x) y)_0 = x1 y2 + x2 y1 (and cyclically), n2 = |a|.|a| + |b|.|b| + |c|.|c|
 * and per label the plain sequential sums of P, P sqrt(3 n2) and P 4 n2 in face order, within chunks of
 * `chunk` faces whose sums are then added in chunk order (numpy's bincount per chunk, added to the totals).
 * Every operation is the one numpy performs, in its order, so the rounding is the same; no fused
 * multiply-add (which would round differently) is allowed here. */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("fp-contract=off")))
#endif
static void
roundoff_loop(const double *v, const void *f, int size, const void *lab, int label_size, size_t m,
              double ox, double oy, double oz, size_t chunk, double *part, double *out, Py_ssize_t n_labels,
              Py_ssize_t *bad)
{
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
    *bad = -1;
    for (size_t start = 0; start < m; start += chunk) {
        size_t stop = m - start > chunk ? start + chunk : m;
        memset(part, 0, (size_t)n_labels * 3 * sizeof(double));
        for (size_t i = start; i < stop; i++) {
            int64_t l = 0;
            if (lab != NULL) {
                l = index_at(lab, label_size, i);
                if (l < 0 || l >= n_labels) {
                    *bad = (Py_ssize_t)i;
                    return;
                }
            }
            const double *pa = v + 3 * index_at(f, size, 3 * i);
            const double *pb = v + 3 * index_at(f, size, 3 * i + 1);
            const double *pc = v + 3 * index_at(f, size, 3 * i + 2);
            double a0 = pa[0] - ox, a1 = pa[1] - oy, a2 = pa[2] - oz;
            double b0 = pb[0] - ox, b1 = pb[1] - oy, b2 = pb[2] - oz;
            double c0 = pc[0] - ox, c1 = pc[1] - oy, c2 = pc[2] - oz;
            double e10 = fabs(b0 - a0), e11 = fabs(b1 - a1), e12 = fabs(b2 - a2);
            double e20 = fabs(c0 - a0), e21 = fabs(c1 - a1), e22 = fabs(c2 - a2);
            a0 = fabs(a0); a1 = fabs(a1); a2 = fabs(a2);
            b0 = fabs(b0); b1 = fabs(b1); b2 = fabs(b2);
            c0 = fabs(c0); c1 = fabs(c1); c2 = fabs(c2);
            double ab0 = a0 + b0, ab1 = a1 + b1, ab2 = a2 + b2;
            double ac0 = a0 + c0, ac1 = a1 + c1, ac2 = a2 + c2;
            double x = a0 * (e11 * e22 + e12 * e21) + a1 * (e12 * e20 + e10 * e22) + a2 * (e10 * e21 + e11 * e20);
            double y = a0 * (ab1 * e22 + ab2 * e21) + a1 * (ab2 * e20 + ab0 * e22) + a2 * (ab0 * e21 + ab1 * e20);
            double z = a0 * (e11 * ac2 + e12 * ac1) + a1 * (e12 * ac0 + e10 * ac2) + a2 * (e10 * ac1 + e11 * ac0);
            double p = 8.0 * x + 2.0 * (y + z);
            double n2 = ((a0 * a0 + a1 * a1) + a2 * a2) + ((b0 * b0 + b1 * b1) + b2 * b2)
                        + ((c0 * c0 + c1 * c1) + c2 * c2);
            double s_norm = sqrt(3.0 * n2);
            double q = 4.0 * n2;
            double *o = part + 3 * (size_t)l;
            o[0] += p;
            o[1] += p * s_norm;
            o[2] += p * q;
        }
        for (size_t k = 0; k < (size_t)n_labels * 3; k++) {
            out[k] += part[k];
        }
    }
}

static PyObject *
accel_roundoff_sums(PyObject *self, PyObject *args)
{
    PyObject *vert_obj, *faces_obj, *labels_obj, *out_obj;
    double ox, oy, oz;
    Py_ssize_t chunk;
    if (!PyArg_ParseTuple(args, "OO(ddd)OOn", &vert_obj, &faces_obj, &ox, &oy, &oz, &labels_obj, &out_obj,
                          &chunk)) {
        return NULL;
    }
    Py_buffer vv, fv, lv, ov;
    double *part = NULL;
    PyObject *result = NULL;
    int have_labels = labels_obj != Py_None, label_size = 0, size;
    Py_ssize_t m;
    if (chunk < 1) {
        PyErr_Format(PyExc_ValueError, "Expected `chunk_size` >= 1, got %zd", chunk);
        return NULL;
    }
    if (PyObject_GetBuffer(vert_obj, &vv, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (get_faces(faces_obj, &fv, &m, &size) < 0) {
        PyBuffer_Release(&vv);
        return NULL;
    }
    if (PyObject_GetBuffer(out_obj, &ov, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        PyBuffer_Release(&vv);
        PyBuffer_Release(&fv);
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
    if (native_code(ov.format) != 'd' || ov.itemsize != 8 || ov.ndim != 2 || ov.shape[1] != 3 || ov.shape[0] < 1) {
        PyErr_SetString(PyExc_ValueError, "Expected `out` as a C-contiguous (n_labels, 3) float64 array");
        goto fail;
    }
    Py_ssize_t n_labels = ov.shape[0];
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
    if (check_indices(fv.buf, size, 3 * (size_t)m, vv.shape[0]) < 0) {
        goto fail;
    }
    part = (double *)calloc((size_t)n_labels * 3, sizeof(double));
    if (part == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    double *out = (double *)ov.buf;
    memset(out, 0, (size_t)n_labels * 3 * sizeof(double));
    Py_ssize_t bad;
    Py_BEGIN_ALLOW_THREADS
    roundoff_loop((const double *)vv.buf, fv.buf, size, have_labels ? lv.buf : NULL, label_size, (size_t)m,
                  ox, oy, oz, (size_t)chunk, part, out, n_labels, &bad);
    Py_END_ALLOW_THREADS
    if (bad >= 0) {
        PyErr_Format(PyExc_ValueError, "Expected labels in 0..%zd, got %lld at position %zd", n_labels - 1,
                     (long long)index_at(lv.buf, label_size, (size_t)bad), bad);
        goto fail;
    }
    result = Py_None;
    Py_INCREF(result);
fail:
    free(part);
    PyBuffer_Release(&vv);
    PyBuffer_Release(&fv);
    PyBuffer_Release(&ov);
    if (have_labels) {
        PyBuffer_Release(&lv);
    }
    return result;
}

/* ======================================================================================================
 * 6. bounds
 *
 * Column minima and maxima of an (n, 3) float64 array in one pass (numpy reduces each column separately),
 * NaN propagating as numpy's min/max do, and whether every coordinate is finite.
 * ====================================================================================================== */

#define BOUNDS_PARALLEL_MIN ((size_t)1 << 17)

typedef struct {
    const double *v;
    size_t n;
    double lo[MAX_THREADS][3], hi[MAX_THREADS][3];
    int nan[MAX_THREADS][3], finite[MAX_THREADS];
} BoundsTask;

static void
bounds_task(void *ctx, int t, int nt)
{
    BoundsTask *b = (BoundsTask *)ctx;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    int nan[3] = {0, 0, 0}, finite = 1;
    for (size_t i = part_start(b->n, t, nt); i < part_start(b->n, t + 1, nt); i++) {
        for (int c = 0; c < 3; c++) {
            double x = b->v[3 * i + c];
            if (x < lo[c]) lo[c] = x;
            if (x > hi[c]) hi[c] = x;
            if (x != x) nan[c] = 1;
            if (x - x != 0.0) finite = 0;      /* NaN or infinite */
        }
    }
    for (int c = 0; c < 3; c++) {
        b->lo[t][c] = lo[c];
        b->hi[t][c] = hi[c];
        b->nan[t][c] = nan[c];
    }
    b->finite[t] = finite;
}

static PyObject *
accel_bounds(PyObject *self, PyObject *args)
{
    PyObject *vert_obj;
    int threads = 1;
    if (!PyArg_ParseTuple(args, "O|i", &vert_obj, &threads)) {
        return NULL;
    }
    Py_buffer vv;
    if (PyObject_GetBuffer(vert_obj, &vv, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (native_code(vv.format) != 'd' || vv.itemsize != 8 || vv.ndim != 2 || vv.shape[1] != 3 || vv.shape[0] < 1) {
        PyErr_SetString(PyExc_ValueError, "Expected `vertices` as a C-contiguous (n, 3) float64 array, n >= 1");
        PyBuffer_Release(&vv);
        return NULL;
    }
    BoundsTask *b = (BoundsTask *)calloc(1, sizeof(BoundsTask));
    if (b == NULL) {
        PyBuffer_Release(&vv);
        return PyErr_NoMemory();
    }
    b->v = (const double *)vv.buf;
    b->n = (size_t)vv.shape[0];
    int nt = thread_count(threads, b->n, BOUNDS_PARALLEL_MIN);
    Py_BEGIN_ALLOW_THREADS
    run_parallel(nt, bounds_task, b);
    Py_END_ALLOW_THREADS
    double lo[3], hi[3];
    int finite = 1;
    for (int c = 0; c < 3; c++) {
        int nan = 0;
        lo[c] = INFINITY;
        hi[c] = -INFINITY;
        for (int t = 0; t < nt; t++) {
            if (b->lo[t][c] < lo[c]) lo[c] = b->lo[t][c];
            if (b->hi[t][c] > hi[c]) hi[c] = b->hi[t][c];
            nan |= b->nan[t][c];
        }
        if (nan) {
            lo[c] = hi[c] = NAN;
        }
    }
    for (int t = 0; t < nt; t++) {
        finite &= b->finite[t];
    }
    free(b);
    PyBuffer_Release(&vv);
    return Py_BuildValue("((ddd)(ddd)O)", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], finite ? Py_True : Py_False);
}

/* ------------------------------------------------------------------------------------------------------
 * 6b. face_measures -- sums of the face areas and perimeters (mesh/precision.volume_rounding_bound)
 *
 * Faces are split into SUM_LANES fixed contiguous lanes, summed lane by lane (threads take lanes t, t + nt,
 * ...) and the lane sums added in lane order, so the result does not depend on the thread count.
 * ------------------------------------------------------------------------------------------------------ */

typedef struct {
    const double *v;
    const void *f;
    int size;
    size_t m;
    int lanes;
    double area[SUM_LANES], perimeter[SUM_LANES];
} MeasureTask;

static void
measure_task(void *ctx, int t, int nt)
{
    MeasureTask *c = (MeasureTask *)ctx;
    for (int lane = t; lane < c->lanes; lane += nt) {
        double area = 0.0, perimeter = 0.0;
        for (size_t i = part_start(c->m, lane, c->lanes); i < part_start(c->m, lane + 1, c->lanes); i++) {
            const double *a = c->v + 3 * index_at(c->f, c->size, 3 * i);
            const double *b = c->v + 3 * index_at(c->f, c->size, 3 * i + 1);
            const double *d = c->v + 3 * index_at(c->f, c->size, 3 * i + 2);
            double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double ad[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
            double bd[3] = {d[0] - b[0], d[1] - b[1], d[2] - b[2]};
            double nx = ab[1] * ad[2] - ab[2] * ad[1], ny = ab[2] * ad[0] - ab[0] * ad[2];
            double nz = ab[0] * ad[1] - ab[1] * ad[0];
            area += 0.5 * sqrt(nx * nx + ny * ny + nz * nz);
            perimeter += sqrt(ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2])
                         + sqrt(ad[0] * ad[0] + ad[1] * ad[1] + ad[2] * ad[2])
                         + sqrt(bd[0] * bd[0] + bd[1] * bd[1] + bd[2] * bd[2]);
        }
        c->area[lane] = area;
        c->perimeter[lane] = perimeter;
    }
}

static PyObject *
accel_face_measures(PyObject *self, PyObject *args)
{
    PyObject *vert_obj, *faces_obj;
    int threads = 1;
    if (!PyArg_ParseTuple(args, "OO|i", &vert_obj, &faces_obj, &threads)) {
        return NULL;
    }
    Py_buffer vv, fv;
    Py_ssize_t m;
    int size;
    if (PyObject_GetBuffer(vert_obj, &vv, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    if (native_code(vv.format) != 'd' || vv.itemsize != 8 || vv.ndim != 2 || vv.shape[1] != 3) {
        PyErr_SetString(PyExc_ValueError, "Expected `vertices` as a C-contiguous (n, 3) float64 array");
        PyBuffer_Release(&vv);
        return NULL;
    }
    if (get_faces(faces_obj, &fv, &m, &size) < 0) {
        PyBuffer_Release(&vv);
        return NULL;
    }
    PyObject *result = NULL;
    if (check_indices(fv.buf, size, 3 * (size_t)m, (int64_t)vv.shape[0]) == 0) {
        MeasureTask *c = (MeasureTask *)calloc(1, sizeof(MeasureTask));
        if (c == NULL) {
            PyErr_NoMemory();
        }
        else {
            c->v = (const double *)vv.buf;
            c->f = fv.buf;
            c->size = size;
            c->m = (size_t)m;
            c->lanes = (size_t)m < SUM_LANES_MIN ? 1 : SUM_LANES;
            int nt = thread_count(threads, (size_t)m, SUM_LANES_MIN);
            Py_BEGIN_ALLOW_THREADS
            run_parallel(nt, measure_task, c);
            Py_END_ALLOW_THREADS
            double area = 0.0, perimeter = 0.0;
            for (int lane = 0; lane < c->lanes; lane++) {
                area += c->area[lane];
                perimeter += c->perimeter[lane];
            }
            free(c);
            result = Py_BuildValue("(dd)", area, perimeter);
        }
    }
    PyBuffer_Release(&vv);
    PyBuffer_Release(&fv);
    return result;
}

/* ======================================================================================================
 * module
 * ====================================================================================================== */

static PyObject *accel_split_steps(PyObject *self, PyObject *args);     /* section 7, after the module */
static PyObject *accel_contact_scan(PyObject *self, PyObject *args);    /* section 8, after the module */
static PyObject *accel_sort_codes(PyObject *self, PyObject *args);      /* section 8, after the module */
static PyObject *accel_edge_twins(PyObject *self, PyObject *args);      /* section 8, after the module */
static PyObject *accel_edge_point_candidates(PyObject *self, PyObject *args);  /* section 9, after the module */
static PyObject *accel_close_groups(PyObject *self, PyObject *args);    /* section 9b, after the module */
static PyObject *accel_surface_cells(PyObject *self, PyObject *args);   /* section 10, after the module */
static PyObject *accel_label_cells(PyObject *self, PyObject *args);     /* section 11, after the module */
static PyObject *accel_certain_parts(PyObject *self, PyObject *args);  /* section 12, after the module */
static PyObject *accel_winding_tree(PyObject *self, PyObject *args);   /* section 13, after the module */

static PyObject *
accel_release_buffers(PyObject *self, PyObject *unused)
{
    pool_drain();
    Py_RETURN_NONE;
}

static PyObject *
accel_kept_buffers(PyObject *self, PyObject *unused)
{
    POOL_LOCK();
    size_t kept = pool_kept;
    POOL_UNLOCK();
    return PyLong_FromSize_t(kept);
}

static PyObject *
accel_set_pool_floor(PyObject *self, PyObject *args)
{
    Py_ssize_t floor_bytes;
    if (!PyArg_ParseTuple(args, "n", &floor_bytes)) {
        return NULL;
    }
    if (floor_bytes < 1) {
        PyErr_Format(PyExc_ValueError, "Expected a positive number of bytes, got %zd", floor_bytes);
        return NULL;
    }
    POOL_LOCK();
    size_t previous = pool_floor;
    pool_floor = (size_t)floor_bytes;
    POOL_UNLOCK();
    return PyLong_FromSize_t(previous);
}

static PyMethodDef accel_methods[] = {
    {"set_pool_floor", accel_set_pool_floor, METH_VARARGS,
     "set_pool_floor(bytes) -> previous\n\nThe smallest scratch mapping the weld and the census keep for the "
     "next call (default 2 MiB; tests lower it so that small inputs reuse old, dirty mappings too)."},
    {"release_buffers", accel_release_buffers, METH_NOARGS,
     "release_buffers()\n\nUnmap the scratch mappings the weld and the census keep for the next call (section "
     "2b, pool_give); they are kept marked MADV_FREE, so the kernel takes them back under memory pressure "
     "anyway."},
    {"kept_buffers", accel_kept_buffers, METH_NOARGS,
     "kept_buffers() -> bytes\n\nBytes of scratch mappings kept for the next weld or census (section 2b)."},
    {"edge_census", accel_edge_census, METH_VARARGS,
     "edge_census(faces, n_vertices, threads=1) -> (edges, boundary, nonmanifold, misoriented, sample_boundary, "
     "sample_nonmanifold, sample_misoriented)\n\nEdge census of (m, 3) int32/int64 faces; each sample is a "
     "list of up to 5 (u, v) vertex pairs, u < v, smallest u * n + v first."},
    {"shell_labels", accel_shell_labels, METH_VARARGS,
     "shell_labels(faces, n_vertices, out) -> count\n\nWrite each face's shell (connected by shared "
     "vertices), numbered by the shell's smallest vertex index, into `out` (m,) int32/int64."},
    {"edge_shell_labels", accel_edge_shell_labels, METH_VARARGS,
     "edge_shell_labels(faces, n_vertices, out) -> count\n\nWrite each face's shell (faces connected through "
     "shared undirected edges), numbered by the shell's first face, into `out` (m,) int32/int64."},
    {"census_shells", accel_census_shells, METH_VARARGS,
     "census_shells(faces, n_vertices, out, threads=1, parallel_min=32768) -> (edges, boundary, nonmanifold, "
     "misoriented, sample_boundary, sample_nonmanifold, sample_misoriented, count)\n\nThe edge census of "
     "edge_census and, when `out` ((m,) int32/int64) is not None, each face's shell into `out` as "
     "checks.shell_labels numbers them (count: the shells; -1 without `out`), from one adjacency on `threads` "
     "threads (one below `parallel_min` faces; tests lower it); the result does not depend on either."},
    {"edge_twins", accel_edge_twins, METH_VARARGS,
     "edge_twins(faces, n_vertices, rounds=1)\n\nThe face-pair check's faces across each edge (section 8, ct_twins), "
     "for the tests: bytes of 3 m int32, twin[3 f + c] the one face running the edge from corner c to c + 1 of f "
     "the other way, -1 when none does, -2 when it is not one."},
    {"sort_codes", accel_sort_codes, METH_VARARGS,
     "sort_codes(words)\n\nThe face-pair check's radix sort (section 8, ct_radix_sort), for the tests: sorts "
     "the (m,) uint64 array `words` in place by their top 33 bits, stable."},
    {"tetra_sums", accel_tetra_sums, METH_VARARGS,
     "tetra_sums(vertices, faces, origin, area_floor, labels, sums, zero, threads=1)\n\nCompensated signed-tetrahedron "
     "sums per label into sums (L, 11) float64 [vol, first xyz, second xx yy zz xy xz yz, area] and zero "
     "(L,) int64 (faces with area <= area_floor / 2); labels (m,) int or None when L == 1; threads (default 1) "
     "only changes the speed."},
    {"roundoff_sums", accel_roundoff_sums, METH_VARARGS,
     "roundoff_sums(vertices, faces, origin, labels, out, chunk_size)\n\nThe sums of integrals.roundoff_bounds "
     "per label into out (L, 3) float64 [sum P, sum P sqrt(3 n2), sum P 4 n2], bit for bit its numpy loop's "
     "(sequential within chunks of chunk_size faces, chunks added in order); labels (m,) int or None when L == 1."},
    {"bounds", accel_bounds, METH_VARARGS,
     "bounds(vertices, threads=1) -> ((lo x, y, z), (hi x, y, z), all_finite)\n\nColumn minima and maxima of "
     "an (n >= 1, 3) C-contiguous float64 array (NaN propagates) and whether every entry is finite."},
    {"face_measures", accel_face_measures, METH_VARARGS,
     "face_measures(vertices, faces, threads=1) -> (area, perimeter)\n\nSums of the face areas and of the face "
     "perimeters of (n, 3) float64 vertices and (m, 3) int32/int64 faces; threads only change the speed."},
    {"split_steps", accel_split_steps, METH_VARARGS,
     "split_steps(moments, drifts, kicks, w, q, tau, t, h, count, torque, frame, q_proto, w_proto, "
     "negligible, separatrix_m1, fallback) -> (w, q, tau)\n\n`count` steps h of the splitting composition "
     "(dynamics/splitting.py), principal frame; see section 7."},
    {"contact_scan", accel_contact_scan, METH_VARARGS,
     "contact_scan(vertices, faces, max_pairs, threads=1, star_faces=0) -> (a, b, kind, candidates, tested, exact, "
     "complete, axis, degenerate)\n\nEvery face pair whose closed boxes meet (but those within one certified star "
     "of at least star_faces faces, when star_faces > 0), found by a bounding-volume hierarchy and "
     "classified (those within a smaller certified star by its certificate); a, b (bytes of int64, a < b) and "
     "kind (bytes of int8, -1: left to numpy) list the pairs that meet; "
     "axis (bytes of int8) and degenerate (bytes of uint8) per face; ""max_pairs < 0: no bound; section 8."},
    {"edge_point_candidates", accel_edge_point_candidates, METH_VARARGS,
     "edge_point_candidates(vertices, edges, points, cell, rtol, gap, threads=1) -> (edge, point)\n\nEvery pair "
     "of an edge of `edges` ((k, 2) int64) and a vertex of `points` ((p,) int64, not an end of it) near its "
     "interior: within max(gap, 2 rtol * distance from the nearer end) of it, to round-off; bytes of int64 each, "
     "by edge; `cell` and `threads` only change the speed (seal.py); section 9."},
    {"close_groups", accel_close_groups, METH_VARARGS,
     "close_groups(points, tolerance) -> bytes or None\n\nFor each of the (k, 3) float64 points, the lowest "
     "index in its group of points joined by distances <= tolerance, transitively (bytes of int64); None when the "
     "grid of cells tolerance / 2 would need more than 21 bits per axis (merge.py); section 9b."},
    {"surface_cells", accel_surface_cells, METH_VARARGS,
     "surface_cells(vertices, faces, origin, h, dims, out)\n\nMark in `out` (bytes of the flat grid dims, C "
     "order) every cell of side h from origin whose closed box meets a face, each face clipped to the grid's "
     "slabs and rows (grid_estimate._surface_cells); section 10."},
    {"label_cells", accel_label_cells, METH_VARARGS,
     "label_cells(mask, dims, out) -> (count, first, sizes)\n\nNumber the face-connected regions of the nonzero "
     "bytes of `mask` (the flat grid dims, C order) 1..count in the order of their first cells, into `out` "
     "((cells,) int32; 0 off the mask), as scipy.ndimage.label with its default structure; `first` and `sizes` "
     "(bytes of int64) are each region's first cell and cell count (grid_estimate._label_regions); section 11."},
    {"certain_parts", accel_certain_parts, METH_VARARGS,
     "certain_parts(centres, margins, closest, gap, sub, rho, limit, reach, core, empty)\n\nFor each cell and "
     "sub-cell, whether a sample's Lipschitz test puts it wholly in the core (`core`, bytes (k, s)) or a "
     "Lipschitz or closest-point test wholly outside it (`empty`, not where `core` is); "
     "offset._certain_parts; section 12."},
    {"winding_tree", accel_winding_tree, METH_VARARGS,
     "winding_tree(points, clusters, levels, triangles, leaf, tolerance, chunk, block, w, err, threads=1)\n\nThe generalized "
     "winding number at each of the (p, 3) float64 points and the bound on its error, into w and err ((p,) "
     "float64), by the treecode of mesh/winding._treecode over its tree (clusters (K, 17) float64, levels (L + 1,) "
     "int64, triangles (m, 9) float64 in the tree's order), its sums split as numpy's chunks of points and blocks of "
     "(point, leaf) pairs; threads only change the speed; section 13."},
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
    if (PyType_Ready(&WelderType) < 0 || PyType_Ready(&PartWelderType) < 0 || PyType_Ready(&ScratchType) < 0) {
        return NULL;
    }
    PyObject *mod = PyModule_Create(&accel_module);
    if (mod == NULL) {
        return NULL;
    }
#if !defined(_WIN32)
    static int fork_handlers = 0;          /* once per process, even if the module is loaded again */
    if (!fork_handlers) {
        fork_handlers = pthread_atfork(pool_before_fork, pool_after_fork, pool_after_fork) == 0;
    }
#endif
    Py_INCREF(&WelderType);
    if (PyModule_AddObject(mod, "Welder", (PyObject *)&WelderType) < 0) {
        Py_DECREF(&WelderType);
        Py_DECREF(mod);
        return NULL;
    }
    Py_INCREF(&PartWelderType);
    if (PyModule_AddObject(mod, "PartWelder", (PyObject *)&PartWelderType) < 0) {
        Py_DECREF(&PartWelderType);
        Py_DECREF(mod);
        return NULL;
    }
    Py_INCREF(&ScratchType);
    if (PyModule_AddObject(mod, "Scratch", (PyObject *)&ScratchType) < 0) {
        Py_DECREF(&ScratchType);
        Py_DECREF(mod);
        return NULL;
    }
#ifdef ACCEL_SOURCE_CRC
    /* CRC-32 of this file as it was compiled (setup.py passes it): _native.accel() compares it with the
     * _accel.c beside the package, so a stale build in a source checkout is set aside, not called */
    PyObject *crc = PyLong_FromUnsignedLong((unsigned long)(ACCEL_SOURCE_CRC));
    if (crc == NULL || PyModule_AddObject(mod, "SOURCE_CRC", crc) < 0) {
        Py_XDECREF(crc);
        Py_DECREF(mod);
        return NULL;
    }
#endif
    return mod;
}

/* ======================================================================================================
 * 7. split_steps -- steps of the splitting integrator (dynamics/splitting.py): exact free flow + kicks
 *
 * The twin of splitting._python_steps and free_flow.free_flow_step on C doubles: the same branches
 * (spherical, symmetric, steady spin, time reversal, asymmetric closed form) and formulas, with the special
 * functions written out here instead of scipy's: K(m) and sn, cn, dn by the arithmetic-geometric mean (the
 * descending Gauss transformation of elliptic.jacobi_sn_cn_dn), Carlson's R_F and R_J by duplication
 * (B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer. Algorithms 10 (1995)
 * 13-26, Algorithms 1 and 4; DLMF 19.36.i).  Results equal the Python path to round-off.  The torque is the
 * caller's torque(t, q, w) -> 3 numbers in mesh axes, called with fresh float64 arrays and rotated to and
 * from the principal frame here (`frame` = (axes, qa_inv), or None when they coincide) as
 * splitting._make_torque does; a non-finite torque raises FloatingPointError (as the Python path does); a
 * state within `separatrix_m1` of the separatrix calls the Python fallback(moments, w, q, h) -> (w, q), as
 * free_flow does.
 * ====================================================================================================== */

#define SPLIT_MAX_ITER 64           /* bound on AGM / duplication iterations (each converges in < 30) */
#define SPLIT_MAX_STAGES 64         /* longest composition accepted (the package's has 11 drifts) */
#define SPLIT_RF_BOUND 403.7494618015396    /* (3 r)^(-1/6), r = 1e-16: Carlson 1995, Algorithm 1 */
#define SPLIT_RJ_BOUND 1847.1570019330606   /* (r / 4)^(-1/6), r = 1e-16: Carlson 1995, Algorithm 4 */

static void
split_quat_mul(const double p[4], const double q[4], double out[4])
{
    double r0 = p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3];
    double r1 = p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2];
    double r2 = p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1];
    double r3 = p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0];
    out[0] = r0;
    out[1] = r1;
    out[2] = r2;
    out[3] = r3;
}

/* q <- q (x) Rot(x, y, z): the active rotation by the rotation vector (x, y, z), angle = its norm */
static void
split_rotate_by(double q[4], double x, double y, double z)
{
    double angle = sqrt(x * x + y * y + z * z);
    if (angle == 0.0) {
        return;
    }
    double s = sin(0.5 * angle) / angle;
    double r[4] = {cos(0.5 * angle), s * x, s * y, s * z};
    split_quat_mul(q, r, q);
}

/* K(m) from m1 = 1 - m > 0: pi / (2 AGM(1, sqrt(m1))) (DLMF 19.8.5) */
static double
split_complete_k(double m1)
{
    double a = 1.0, b = sqrt(m1);
    /* a_{n+1} - b_{n+1} ~ (a_n - b_n)^2 / (8 a): below 1e-9 a the mean (a + b)/2 is the limit to < 2e-19 */
    for (int i = 0; i < SPLIT_MAX_ITER && fabs(a - b) > 1e-9 * a; i++) {
        double next = 0.5 * (a + b);
        b = sqrt(a * b);
        a = next;
    }
    return M_PI / (a + b);
}

/* sn, cn, dn of u by the AGM (DLMF 22.20.ii), u reduced by 2K first; m1 = 1 - m kept exact */
static void
split_jacobi(double u, double m, double m1, double kk, double *sn, double *cn, double *dn)
{
    double turns = nearbyint(u / (2.0 * kk));
    double r = u - 2.0 * kk * turns;
    double sign = fmod(turns, 2.0) != 0.0 ? -1.0 : 1.0;     /* sn(u + 2K) = -sn u, cn(u + 2K) = -cn u */
    if (m <= 0.0) {
        *sn = sign * sin(r);
        *cn = sign * cos(r);
        *dn = 1.0;
        return;
    }
    double a[SPLIT_MAX_ITER + 1], b[SPLIT_MAX_ITER + 1], c[SPLIT_MAX_ITER + 1];
    a[0] = 1.0;
    b[0] = sqrt(m1);
    c[0] = sqrt(m);
    int n = 0;
    /* stop at c <= 2^-53 a (as Cephes' ellpj): a stricter bound can stall at a one-ulp a - b for ever */
    while (n < SPLIT_MAX_ITER && fabs(c[n]) > 0x1p-53 * a[n]) {
        a[n + 1] = 0.5 * (a[n] + b[n]);
        b[n + 1] = sqrt(a[n] * b[n]);
        c[n + 1] = 0.5 * (a[n] - b[n]);
        n++;
    }
    double phi = ldexp(a[n] * r, n);
    for (int i = n; i > 0; i--) {
        /* asin(c sin(phi) / a) written as atan2 with a^2 - c^2 = b^2 (accurate near m -> 1) */
        double sp = sin(phi), cp = cos(phi);
        phi = 0.5 * (phi + atan2(c[i] * sp, sqrt((a[i] * cp) * (a[i] * cp) + (b[i] * sp) * (b[i] * sp))));
    }
    double s = sin(phi), co = cos(phi);
    *sn = sign * s;
    *cn = sign * co;
    *dn = sqrt(co * co + m1 * s * s);
}

/* Carlson's R_F(x, y, z), x, y, z >= 0, at most one zero (Carlson 1995, Algorithm 1, r = 1e-16) */
static double
split_carlson_rf(double x, double y, double z)
{
    double x0 = x, y0 = y;
    double a0 = (x + y + z) / 3.0;
    double bound = SPLIT_RF_BOUND * fmax(fabs(a0 - x), fmax(fabs(a0 - y), fabs(a0 - z)));
    double a = a0, scale = 1.0;                     /* scale = 4^-n */
    for (int i = 0; i < SPLIT_MAX_ITER && scale * bound >= fabs(a); i++) {
        double sx = sqrt(x), sy = sqrt(y), sz = sqrt(z);
        double lam = sx * sy + sx * sz + sy * sz;
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        a = 0.25 * (a + lam);
        scale *= 0.25;
    }
    double dx = (a0 - x0) * scale / a, dy = (a0 - y0) * scale / a;
    double dz = -dx - dy;
    double e2 = dx * dy - dz * dz, e3 = dx * dy * dz;
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / sqrt(a);
}

/* R_C(1, 1 + e), e > -1, in closed form (DLMF 19.2.19-20) */
static double
split_carlson_rc1(double e)
{
    if (e > 0.0) {
        double s = sqrt(e);
        return atan(s) / s;
    }
    if (e < 0.0) {
        double s = sqrt(-e);
        return atanh(s) / s;
    }
    return 1.0;
}

/* Carlson's R_J(x, y, z, p), x, y, z >= 0 (at most one zero), p > 0 (Carlson 1995, Algorithm 4, r = 1e-16) */
static double
split_carlson_rj(double x, double y, double z, double p)
{
    double x0 = x, y0 = y, z0 = z;
    double a0 = (x + y + z + 2.0 * p) / 5.0;
    double delta = (p - x) * (p - y) * (p - z);
    double bound = SPLIT_RJ_BOUND * fmax(fmax(fabs(a0 - x), fabs(a0 - y)), fmax(fabs(a0 - z), fabs(a0 - p)));
    double a = a0, scale = 1.0, sum = 0.0;        /* scale = 4^-m */
    for (int i = 0; i < SPLIT_MAX_ITER && scale * bound >= fabs(a); i++) {
        double sx = sqrt(x), sy = sqrt(y), sz = sqrt(z), sp = sqrt(p);
        double lam = sx * sy + sx * sz + sy * sz;
        double d = (sp + sx) * (sp + sy) * (sp + sz);
        double e = scale * scale * scale * delta / (d * d);
        sum += scale / d * split_carlson_rc1(e);
        x = 0.25 * (x + lam);
        y = 0.25 * (y + lam);
        z = 0.25 * (z + lam);
        p = 0.25 * (p + lam);
        a = 0.25 * (a + lam);
        scale *= 0.25;
    }
    double dx = (a0 - x0) * scale / a, dy = (a0 - y0) * scale / a, dz = (a0 - z0) * scale / a;
    double dp = -0.5 * (dx + dy + dz);
    double e2 = dx * dy + dx * dz + dy * dz - 3.0 * dp * dp;
    double e3 = dx * dy * dz + 2.0 * e2 * dp + 4.0 * dp * dp * dp;
    double e4 = (2.0 * dx * dy * dz + e2 * dp + 3.0 * dp * dp * dp) * dp;
    double e5 = dx * dy * dz * dp * dp;
    double series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
                    - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0;
    return scale * series / (a * sqrt(a)) + 6.0 * sum;
}

/* Pi(n; phi | m) for |phi| <= pi/2 from s = sin(phi), c = cos(phi) >= 0 (DLMF 19.25.14) */
static double
split_pi_reduced(double s, double c, double n, double m1)
{
    double c2 = c * c, s2 = s * s;
    double delta2 = c2 + m1 * s2;
    return s * split_carlson_rf(c2, delta2, 1.0) + (n / 3.0) * s * s2 * split_carlson_rj(c2, delta2, 1.0, 1.0 - n * s2);
}

/* rows of the nodal frame of L: (L x d)/|L x d|, L^ x row1, L^ (free_flow._nodal_rows) */
static void
split_nodal_rows(double lx, double ly, double lz, const double d[3], double mom, double r[3][3])
{
    double ax = ly * d[2] - lz * d[1], ay = lz * d[0] - lx * d[2], az = lx * d[1] - ly * d[0];
    double p = sqrt(ax * ax + ay * ay + az * az);
    ax /= p;
    ay /= p;
    az /= p;
    double ux = lx / mom, uy = ly / mom, uz = lz / mom;
    r[0][0] = ax; r[0][1] = ay; r[0][2] = az;
    r[1][0] = uy * az - uz * ay; r[1][1] = uz * ax - ux * az; r[1][2] = ux * ay - uy * ax;
    r[2][0] = ux; r[2][1] = uy; r[2][2] = uz;
}

/* scalar-first quaternion of a row-major rotation matrix (Shepperd's method, free_flow._matrix_quat) */
static void
split_matrix_quat(const double r[9], double out[4])
{
    double trace = r[0] + r[4] + r[8];
    double s;
    if (trace >= fmax(r[0], fmax(r[4], r[8]))) {
        s = 2.0 * sqrt(1.0 + trace);
        out[0] = 0.25 * s; out[1] = (r[7] - r[5]) / s; out[2] = (r[2] - r[6]) / s; out[3] = (r[3] - r[1]) / s;
    } else if (r[0] >= r[4] && r[0] >= r[8]) {
        s = 2.0 * sqrt(1.0 + r[0] - r[4] - r[8]);
        out[0] = (r[7] - r[5]) / s; out[1] = 0.25 * s; out[2] = (r[1] + r[3]) / s; out[3] = (r[2] + r[6]) / s;
    } else if (r[4] >= r[8]) {
        s = 2.0 * sqrt(1.0 - r[0] + r[4] - r[8]);
        out[0] = (r[2] - r[6]) / s; out[1] = (r[1] + r[3]) / s; out[2] = 0.25 * s; out[3] = (r[5] + r[7]) / s;
    } else {
        s = 2.0 * sqrt(1.0 - r[0] - r[4] + r[8]);
        out[0] = (r[3] - r[1]) / s; out[1] = (r[2] + r[6]) / s; out[2] = (r[5] + r[7]) / s; out[3] = 0.25 * s;
    }
}

typedef struct {
    double moments[3];
    double negligible;          /* torque_free.NEGLIGIBLE_COMPONENT */
    double separatrix_m1;       /* free_flow.NEAR_SEPARATRIX_M1 */
    PyObject *fallback;         /* free_flow.free_flow_step */
} SplitFlow;

/* the Python fallback near the separatrix; 0 on success, -1 with a Python error set */
static int
split_fallback(const SplitFlow *flow, double w[3], double q[4], double h)
{
    PyObject *res = PyObject_CallFunction(flow->fallback, "(ddd)(ddd)(dddd)d", flow->moments[0],
                                          flow->moments[1], flow->moments[2], w[0], w[1], w[2], q[0], q[1],
                                          q[2], q[3], h);
    if (res == NULL) {
        return -1;
    }
    double wn[3], qn[4];
    int ok = PyArg_ParseTuple(res, "(ddd)(dddd)", &wn[0], &wn[1], &wn[2], &qn[0], &qn[1], &qn[2], &qn[3]);
    Py_DECREF(res);
    if (!ok) {
        return -1;
    }
    memcpy(w, wn, sizeof wn);
    memcpy(q, qn, sizeof qn);
    return 0;
}

/* Q(h) = Q0 Rot(L^, M h / I_perp) Rot(e_k, beta h), w(h) = Rot(e_k, -beta h) w0 (free_flow._symmetric_step) */
static void
split_symmetric(const double mo[3], double w[3], double q[4], double h, int k, double i_perp)
{
    double big_l[3] = {mo[0] * w[0], mo[1] * w[1], mo[2] * w[2]};
    double beta = (1.0 / mo[k] - 1.0 / i_perp) * big_l[k];
    double scale = h / i_perp;
    split_rotate_by(q, big_l[0] * scale, big_l[1] * scale, big_l[2] * scale);
    double spin[3] = {0.0, 0.0, 0.0};
    spin[k] = beta * h;
    split_rotate_by(q, spin[0], spin[1], spin[2]);
    double cb = cos(beta * h), sb = sin(beta * h);
    int i = (k + 1) % 3, j = (k + 2) % 3;
    double wi = w[i], wj = w[j];
    w[i] = cb * wi + sb * wj;
    w[j] = -sb * wi + cb * wj;
}

/* exact torque-free motion over h, principal frame (free_flow.free_flow_step); -1 with a Python error set */
static int
split_free_flow(const SplitFlow *flow, double w[3], double q[4], double h)
{
    double i1 = flow->moments[0], i2 = flow->moments[1], i3 = flow->moments[2];
    double w1 = w[0], w2 = w[1], w3 = w[2];
    double big = fmax(fabs(w1), fmax(fabs(w2), fabs(w3)));
    if (big == 0.0 || h == 0.0) {
        return 0;
    }
    if (i1 == i3) {
        split_rotate_by(q, w1 * h, w2 * h, w3 * h);
        return 0;
    }
    if (i1 == i2) {
        split_symmetric(flow->moments, w, q, h, 2, i1);
        return 0;
    }
    if (i2 == i3) {
        split_symmetric(flow->moments, w, q, h, 0, i3);
        return 0;
    }
    double tiny = flow->negligible * big;
    if ((fabs(w1) > tiny) + (fabs(w2) > tiny) + (fabs(w3) > tiny) <= 1) {   /* steady spin */
        split_rotate_by(q, w1 * h, w2 * h, w3 * h);
        return 0;
    }
    if (h < 0.0) {          /* time reversal: w(-h; w0) = -w(h; -w0), Q(-h; w0, Q0) = Q(h; -w0, Q0) */
        w[0] = -w1;
        w[1] = -w2;
        w[2] = -w3;
        if (split_free_flow(flow, w, q, -h) < 0) {
            return -1;
        }
        w[0] = -w[0];
        w[1] = -w[1];
        w[2] = -w[2];
        return 0;
    }
    double j1, j2, j3, v1, v2, v3;
    int d_axis;
    if (i3 * (i3 - i2) * w3 * w3 - i1 * (i2 - i1) * w1 * w1 >= 0.0) {
        j1 = i1; j2 = i2; j3 = i3; v1 = w1; v2 = w2; v3 = w3;
        d_axis = 2;
    } else {
        j1 = i3; j2 = i2; j3 = i1; v1 = w3; v2 = -w2; v3 = w1;
        d_axis = 0;
    }
    double d_sign = 1.0;
    if (v3 < 0.0) {
        v1 = -v1;
        v3 = -v3;
        d_sign = -1.0;
    }
    double k0 = j1 * (j3 - j1) * v1 * v1 + j2 * (j3 - j2) * v2 * v2;
    double k1 = j2 * (j2 - j1) * v2 * v2 + j3 * (j3 - j1) * v3 * v3;
    double gap = j3 * (j3 - j2) * v3 * v3 - j1 * (j2 - j1) * v1 * v1;
    double m1 = fmax((j3 - j1) * gap / ((j3 - j2) * k1), 0.0);
    double m = (j2 - j1) * k0 / ((j3 - j2) * k1);
    if (m1 < 0.5) {
        m = 1.0 - m1;
    } else {
        m1 = 1.0 - m;
    }
    if (m1 < flow->separatrix_m1) {
        return split_fallback(flow, w, q, h);
    }
    double a = sqrt(k0 / (j1 * (j3 - j1)));
    double b = sqrt(k0 / (j2 * (j3 - j2)));
    double c = sqrt(k1 / (j3 * (j3 - j1)));
    double lam = sqrt((j3 - j2) * k1 / (j1 * j2 * j3));
    double sigma = j3 > j2 ? 1.0 : -1.0;
    double s0 = sigma * v2 / b, c0 = v1 / a;
    double norm = hypot(s0, c0);
    s0 /= norm;
    c0 /= norm;
    double d0 = sqrt(c0 * c0 + m1 * s0 * s0);
    double kk = split_complete_k(m1);
    double v = lam * h;
    double turns = floor(v / (2.0 * kk));       /* whole half-periods of sn: am advances by pi each */
    double vr = v - 2.0 * kk * turns;
    double sv, cv, dv;
    split_jacobi(vr, m, m1, kk, &sv, &cv, &dv);
    if (fmod(turns, 2.0) != 0.0) {
        sv = -sv;
        cv = -cv;
    }
    double den = 1.0 - m * s0 * s0 * sv * sv;
    double s1 = (s0 * cv * dv + sv * c0 * d0) / den;
    double c1 = (c0 * cv - s0 * d0 * sv * dv) / den;
    double d1 = (d0 * dv - m * s0 * c0 * sv * cv) / den;
    double n = -j3 * (j2 - j1) / (j1 * (j3 - j2));
    double phi0 = atan2(s0, c0);
    double delta = fmod(atan2(s1, c1) - phi0 - M_PI * turns, 2.0 * M_PI);
    if (delta < 0.0) {
        delta += 2.0 * M_PI;                    /* Python's % is non-negative for a positive modulus */
    }
    if (delta > 1.5 * M_PI) {
        delta -= 2.0 * M_PI;
    }
    double phi1 = phi0 + M_PI * turns + delta;
    double half0 = nearbyint(phi0 / M_PI), half1 = nearbyint(phi1 / M_PI);   /* round half to even */
    double sign0 = fmod(half0, 2.0) != 0.0 ? -1.0 : 1.0;
    double sign1 = fmod(half1, 2.0) != 0.0 ? -1.0 : 1.0;
    double big_pi = split_pi_reduced(sign1 * s1, fabs(c1), n, m1) - split_pi_reduced(sign0 * s0, fabs(c0), n, m1);
    if (half1 != half0) {
        double complete = split_carlson_rf(0.0, m1, 1.0) + (n / 3.0) * split_carlson_rj(0.0, m1, 1.0, 1.0 - n);
        big_pi += 2.0 * (half1 - half0) * complete;
    }
    double mom = sqrt((j1 * v1) * (j1 * v1) + (j2 * v2) * (j2 * v2) + (j3 * v3) * (j3 * v3));
    double psi = mom * h / j3 + mom * (j3 - j1) / (j1 * j3 * lam) * big_pi;
    double u1 = a * c1, u2 = sigma * b * s1, u3 = c * d1;
    if (d_sign < 0.0) {
        u1 = -u1;
        u3 = -u3;
    }
    double out[3];
    if (d_axis == 2) {
        out[0] = u1; out[1] = u2; out[2] = u3;
    } else {
        out[0] = u3; out[1] = -u2; out[2] = u1;
    }
    double d[3] = {0.0, 0.0, 0.0};
    d[d_axis] = d_sign;
    double r[3][3], t[3][3];
    split_nodal_rows(i1 * w1, i2 * w2, i3 * w3, d, mom, r);
    split_nodal_rows(i1 * out[0], i2 * out[1], i3 * out[2], d, mom, t);
    double cz = cos(psi), sz = sin(psi);
    double col1[3], col2[3], rot[9], dq[4];
    for (int i = 0; i < 3; i++) {
        col1[i] = cz * r[0][i] + sz * r[1][i];
        col2[i] = -sz * r[0][i] + cz * r[1][i];
    }
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            rot[3 * i + j] = col1[i] * t[0][j] + col2[i] * t[1][j] + r[2][i] * t[2][j];
        }
    }
    split_matrix_quat(rot, dq);
    split_quat_mul(q, dq, q);
    w[0] = out[0];
    w[1] = out[1];
    w[2] = out[2];
    return 0;
}

/* The caller's torque, in mesh axes: torque(t, q_mesh (4,) ndarray, w_mesh (3,) ndarray) -> 3 numbers.
 * q_mesh = q (x) qa_inv, w_mesh = axes w, tau_principal = axes^T tau_mesh (splitting._make_torque), skipped
 * when the principal axes are the mesh axes.  Fresh arrays per call (copies of the prototypes). */
typedef struct {
    PyObject *torque;           /* callable or Py_None */
    int rotated;
    double axes[9];             /* principal -> mesh, row-major */
    double qa_inv[4];
    PyObject *q_proto, *w_proto;
    PyObject *q_arr, *w_arr;    /* owned; reused only while nobody else holds a reference (see split_array) */
} SplitTorque;

/* *slot <- an array holding `values`: the previous one when this function holds its only reference (the
 * torque kept neither it nor a view of it, so no one can see it change), else a fresh copy of proto */
static int
split_array(PyObject **slot, PyObject *proto, const double *values, Py_ssize_t n)
{
    if (*slot != NULL && Py_REFCNT(*slot) != 1) {
        Py_CLEAR(*slot);
    }
    if (*slot == NULL) {
        *slot = PyObject_CallMethod(proto, "copy", NULL);
        if (*slot == NULL) {
            return -1;
        }
    }
    Py_buffer view;
    if (PyObject_GetBuffer(*slot, &view, PyBUF_WRITABLE | PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
        Py_CLEAR(*slot);
        return -1;
    }
    if (view.len != n * (Py_ssize_t)sizeof(double) || view.format == NULL || strcmp(view.format, "d") != 0) {
        PyBuffer_Release(&view);
        Py_CLEAR(*slot);
        PyErr_SetString(PyExc_ValueError, "Expected float64 prototype arrays of shapes (4,) and (3,)");
        return -1;
    }
    memcpy(view.buf, values, (size_t)n * sizeof(double));
    PyBuffer_Release(&view);
    return 0;
}

/* three floats from the torque's result: a float64 C-contiguous buffer of 3, else any sequence of 3 numbers */
static int
split_read_torque(PyObject *res, double out[3])
{
    if (PyObject_CheckBuffer(res)) {
        Py_buffer view;
        if (PyObject_GetBuffer(res, &view, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) == 0) {
            int ok = view.len == 3 * (Py_ssize_t)sizeof(double) && view.format != NULL
                     && strcmp(view.format, "d") == 0;
            if (ok) {
                memcpy(out, view.buf, 3 * sizeof(double));
            }
            PyBuffer_Release(&view);
            if (ok) {
                return 0;
            }
        } else {
            PyErr_Clear();
        }
    }
    PyObject *seq = PySequence_Fast(res, "Expected the torque to return 3 numbers");
    if (seq == NULL) {
        return -1;
    }
    if (PySequence_Fast_GET_SIZE(seq) != 3) {
        PyErr_Format(PyExc_ValueError, "Expected the torque to return 3 numbers, got %zd",
                     PySequence_Fast_GET_SIZE(seq));
        Py_DECREF(seq);
        return -1;
    }
    for (int i = 0; i < 3; i++) {
        out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, i));
    }
    Py_DECREF(seq);
    return PyErr_Occurred() ? -1 : 0;
}

/* tau <- torque at (time, q, w), principal frame; zero without torque; -1 with a Python error set */
static int
split_torque(SplitTorque *st, double time, const double q[4], const double w[3], double tau[3])
{
    if (st->torque == Py_None) {
        tau[0] = tau[1] = tau[2] = 0.0;
        return 0;
    }
    double qm[4], wm[3], tm[3];
    const double *a = st->axes;
    if (st->rotated) {
        split_quat_mul(q, st->qa_inv, qm);
        wm[0] = a[0] * w[0] + a[1] * w[1] + a[2] * w[2];
        wm[1] = a[3] * w[0] + a[4] * w[1] + a[5] * w[2];
        wm[2] = a[6] * w[0] + a[7] * w[1] + a[8] * w[2];
    } else {
        memcpy(qm, q, sizeof qm);
        memcpy(wm, w, sizeof wm);
    }
    if (split_array(&st->q_arr, st->q_proto, qm, 4) < 0 || split_array(&st->w_arr, st->w_proto, wm, 3) < 0) {
        return -1;
    }
    PyObject *time_obj = PyFloat_FromDouble(time);
    if (time_obj == NULL) {
        return -1;
    }
    PyObject *res = PyObject_CallFunctionObjArgs(st->torque, time_obj, st->q_arr, st->w_arr, NULL);
    Py_DECREF(time_obj);
    if (res == NULL) {
        return -1;
    }
    int status = split_read_torque(res, tm);
    Py_DECREF(res);
    if (status < 0) {
        return -1;
    }
    if (!isfinite(tm[0]) || !isfinite(tm[1]) || !isfinite(tm[2])) {
        char message[160];
        snprintf(message, sizeof message, "the torque is not finite at t = %.17g s: (%g, %g, %g)", time, tm[0],
                 tm[1], tm[2]);
        PyErr_SetString(PyExc_FloatingPointError, message);
        return -1;
    }
    if (st->rotated) {
        tau[0] = a[0] * tm[0] + a[3] * tm[1] + a[6] * tm[2];
        tau[1] = a[1] * tm[0] + a[4] * tm[1] + a[7] * tm[2];
        tau[2] = a[2] * tm[0] + a[5] * tm[1] + a[8] * tm[2];
    } else {
        memcpy(tau, tm, sizeof tm);
    }
    return 0;
}

static int
split_read_coefficients(PyObject *obj, double *out, Py_ssize_t *count, const char *name)
{
    PyObject *seq = PySequence_Fast(obj, "coefficients must be a sequence");
    if (seq == NULL) {
        return -1;
    }
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    if (n < 1 || n > SPLIT_MAX_STAGES + 1) {
        PyErr_Format(PyExc_ValueError, "Expected 1 to %d %s, got %zd", SPLIT_MAX_STAGES + 1, name, n);
        Py_DECREF(seq);
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, i));
    }
    Py_DECREF(seq);
    *count = n;
    return PyErr_Occurred() ? -1 : 0;
}

static PyObject *
accel_split_steps(PyObject *self, PyObject *args)
{
    (void)self;
    SplitFlow flow;
    SplitTorque st;
    PyObject *drift_obj, *kick_obj, *frame;
    double w[3], q[4], tau[3], t0, h;
    Py_ssize_t count;
    double drifts[SPLIT_MAX_STAGES + 1], kicks[SPLIT_MAX_STAGES + 1];
    Py_ssize_t n_drifts, n_kicks;
    if (!PyArg_ParseTuple(args, "(ddd)OO(ddd)(dddd)(ddd)ddnOOOOddO", &flow.moments[0], &flow.moments[1],
                          &flow.moments[2], &drift_obj, &kick_obj, &w[0], &w[1], &w[2], &q[0], &q[1], &q[2],
                          &q[3], &tau[0], &tau[1], &tau[2], &t0, &h, &count, &st.torque, &frame, &st.q_proto,
                          &st.w_proto, &flow.negligible, &flow.separatrix_m1, &flow.fallback)) {
        return NULL;
    }
    if (split_read_coefficients(drift_obj, drifts, &n_drifts, "drifts") < 0
        || split_read_coefficients(kick_obj, kicks, &n_kicks, "kicks") < 0) {
        return NULL;
    }
    if (n_kicks != n_drifts + 1) {
        PyErr_Format(PyExc_ValueError, "Expected len(kicks) == len(drifts) + 1, got %zd and %zd", n_kicks,
                     n_drifts);
        return NULL;
    }
    if (st.torque != Py_None && !PyCallable_Check(st.torque)) {
        PyErr_SetString(PyExc_TypeError, "Expected `torque` to be callable or None");
        return NULL;
    }
    if (!PyCallable_Check(flow.fallback)) {
        PyErr_SetString(PyExc_TypeError, "Expected `fallback` to be callable");
        return NULL;
    }
    st.rotated = frame != Py_None;
    if (st.rotated && !PyArg_ParseTuple(frame, "(ddddddddd)(dddd)", &st.axes[0], &st.axes[1], &st.axes[2],
                                        &st.axes[3], &st.axes[4], &st.axes[5], &st.axes[6], &st.axes[7],
                                        &st.axes[8], &st.qa_inv[0], &st.qa_inv[1], &st.qa_inv[2],
                                        &st.qa_inv[3])) {
        return NULL;
    }
    const double *mo = flow.moments;
    st.q_arr = st.w_arr = NULL;
    PyObject *result = NULL;
    for (Py_ssize_t step = 0; step < count; step++) {
        if (PyErr_CheckSignals() < 0) {         /* Ctrl-C also without a torque (no Python code runs then) */
            goto done;
        }
        double time = t0 + (double)step * h;
        for (Py_ssize_t i = 0; i < n_drifts; i++) {
            double hb = kicks[i] * h;
            w[0] += hb * tau[0] / mo[0];
            w[1] += hb * tau[1] / mo[1];
            w[2] += hb * tau[2] / mo[2];
            if (split_free_flow(&flow, w, q, drifts[i] * h) < 0) {
                goto done;
            }
            time += drifts[i] * h;
            if (split_torque(&st, time, q, w, tau) < 0) {
                goto done;
            }
        }
        double hb = kicks[n_drifts] * h;
        w[0] += hb * tau[0] / mo[0];
        w[1] += hb * tau[1] / mo[1];
        w[2] += hb * tau[2] / mo[2];
        double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);    /* round-off only */
        q[0] /= norm;
        q[1] /= norm;
        q[2] /= norm;
        q[3] /= norm;
    }
    result = Py_BuildValue("(ddd)(dddd)(ddd)", w[0], w[1], w[2], q[0], q[1], q[2], q[3], tau[0], tau[1], tau[2]);
done:
    Py_XDECREF(st.q_arr);
    Py_XDECREF(st.w_arr);
    return result;
}

/* ======================================================================================================
 * 8. contact_scan -- exact classification of face pairs (mesh/intersect.py, the twin of _classify)
 *
 * Every decision is the sign of orient3d / orient2d of input coordinates.  Each is evaluated in doubles with
 * the static error bound of mesh/intersect.py (10 u times the permanent for orient3d, 6 u for orient2d,
 * u = 2^-53; valid because the caller guarantees every nonzero coordinate magnitude lies in [2^-240, 2^299]);
 * within the bound the determinant is recomputed exactly with floating-point expansions (Shewchuk 1997:
 * Two-Sum, Two-Product by fused multiply-add, Grow-Expansion with zero elimination): the nine differences
 * are exact two-term expansions, each of the six triple products of their parts is an exact sum of four
 * doubles, and all of them are summed into one nonoverlapping expansion whose largest component gives the
 * sign.  Exactness of every Two-Product holds in that coordinate range (all quantities are multiples of
 * 2^-876, representable).  A pair whose expansion would outgrow CONTACT_EXP_MAX components gets kind -1 and
 * the caller classifies it on the numpy path.  The candidate pairs come from a bounding-volume hierarchy
 * instead of the numpy path's grid: the same set of pairs (those whose closed boxes meet), in another order.
 * With star_faces > 0 the pairs within one certified star (ct_stars; mesh/intersect.py, "Stars", proves they
 * meet only in what they share) are left out on both paths, here also whole node pairs whose faces all hold
 * one certified vertex (CtNode.apex), so a fan cap of k faces costs O(k) instead of k(k - 1)/2 pairs.  Here
 * also the star of every vertex of at least CT_STAR_MIN (3) faces is tried: a pair within a small certified
 * star (fewer than star_faces faces) is still enumerated and counted as a candidate and as tested, as the numpy
 * path counts it, but decided "none" by the certificate instead of rebuilding and testing both faces (on a
 * clean mesh that is nearly every candidate pair: the faces sharing a corner).  With patches (and no work
 * bound) a node whose faces form a certified patch (ct_patches; mesh/intersect.py, "Patches") is not descended
 * with itself: on a smooth surface that leaves out nearly every pair of faces sharing a corner, and the
 * counts fall below the numpy path's.  Then the patches come first (the faces across each edge, the
 * hierarchy, the patches) and only the stars of vertices whose faces are not all in one certified patch are
 * certified (the others would decide no pair), the node apexes last.
 * ====================================================================================================== */

#define CONTACT_EXP_MAX 192

/* Stage timing of contact_scan for profiling: with INERTIA_TOOL_CT_PROFILE set in the environment each call
 * prints the CPU time (all threads) of its stages (Morton codes, sort, preparation, then with patches the
 * vertices' face lists, the faces across each edge, the hierarchy, the patches, the star certificates, the
 * apexes and per-face star bits; else the stars and the hierarchy together; the traversal) to stderr;
 * INERTIA_TOOL_CT_PROFILE=wall prints wall times instead (what the stages' threads save, on a quiet machine). */
#if defined(__linux__) || defined(__APPLE__)
#include <time.h>
static double
ct_clock(int wall)
{
    struct timespec ts;
    clock_gettime(wall ? CLOCK_MONOTONIC : CLOCK_PROCESS_CPUTIME_ID, &ts);     /* CPU time: the machine is shared */
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
#else
static double
ct_clock(int wall)
{
    (void)wall;
    return 0.0;
}
#endif

/* Profiling only (INERTIA_TOOL_CT_PROFILE): the process's resident MB now (VmRSS) and at most so far (VmHWM),
 * from /proc (0 elsewhere), so that the profile names the phase that sets the check's high point. */
static void
ct_resident_mb(double *now, double *peak)
{
    *now = *peak = 0.0;
#if defined(__linux__)
    FILE *fh = fopen("/proc/self/status", "r");
    char line[256];
    if (fh == NULL) return;
    while (fgets(line, sizeof(line), fh) != NULL) {
        if (strncmp(line, "VmHWM:", 6) == 0) *peak = atof(line + 6) * 1024.0 / 1e6;
        if (strncmp(line, "VmRSS:", 6) == 0) *now = atof(line + 6) * 1024.0 / 1e6;
    }
    fclose(fh);
#endif
}
#define CONTACT_O3 (10.0 * 1.1102230246251565e-16)
#define CONTACT_O2 (6.0 * 1.1102230246251565e-16)

typedef struct {
    int n;
    int overflow;
    double e[CONTACT_EXP_MAX];
} Expansion;

/* Two-Sum needs each operation rounded once to double, in the written order.  Where doubles are evaluated in
 * their own precision (FLT_EVAL_METHOD 0: SSE2 on x86-64, AArch64) and the compiler may not reassociate
 * (no -ffast-math), plain arithmetic does that; elsewhere (x87's excess precision, fast-math) the sum is
 * forced through memory (volatile), which costs a store and a load per Two-Sum: on a fan-capped cylinder's
 * check (every side quad's fourth corner exactly on the plane of its other three) about a third of the
 * exact stage's time. */
#include <float.h>
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0 && !defined(__FAST_MATH__)
#define CT_EXACT_DOUBLE double
#else
#define CT_EXACT_DOUBLE volatile double
#endif

static inline void
ct_two_sum(double a, double b, double *x, double *y)
{
    CT_EXACT_DOUBLE s = a + b;
    double bv = s - a;
    double av = s - bv;
    *x = s;
    *y = (a - av) + (b - bv);
}

/* Grow-Expansion with zero elimination: h += b, h nonoverlapping before and after. */
static void
ct_grow(Expansion *h, double b)
{
    if (b == 0.0) {
        return;
    }
    double q = b;
    int k = 0;
    for (int i = 0; i < h->n; i++) {
        double s, t;
        ct_two_sum(q, h->e[i], &s, &t);
        q = s;
        if (t != 0.0) {
            h->e[k++] = t;
        }
    }
    if (q != 0.0) {
        if (k >= CONTACT_EXP_MAX) {
            h->overflow = 1;
            return;
        }
        h->e[k++] = q;
    }
    h->n = k;
}

/* h += sign * p * q * r exactly (four doubles). */
static void
ct_add_product3(Expansion *h, double sign, double p, double q, double r)
{
    if (p == 0.0 || q == 0.0 || r == 0.0) {
        return;
    }
    double P = p * q;
    double e = fma(p, q, -P);
    double A = P * r;
    double B = fma(P, r, -A);
    ct_grow(h, sign * A);
    ct_grow(h, sign * B);
    if (e != 0.0) {
        double C = e * r;
        double D = fma(e, r, -C);
        ct_grow(h, sign * C);
        ct_grow(h, sign * D);
    }
}

static void
ct_add_product2(Expansion *h, double sign, double p, double q)
{
    if (p == 0.0 || q == 0.0) {
        return;
    }
    double P = p * q;
    ct_grow(h, sign * P);
    ct_grow(h, sign * fma(p, q, -P));
}

/* Sign of a nonoverlapping expansion (its largest component is last), 2 when it overflowed. */
static int
ct_sign(const Expansion *h)
{
    if (h->overflow) {
        return 2;
    }
    if (h->n == 0) {
        return 0;
    }
    return h->e[h->n - 1] > 0 ? 1 : -1;
}

typedef struct {
    long exact;       /* evaluations decided by the exact stage */
    int failed;       /* an expansion overflowed: the pair goes back to the numpy path */
} CtStats;

/* The sign of an exact-stage expansion, counted in ``st``; an overflow marks the pair failed (sign 0). */
static int
ct_exact_sign(const Expansion *h, CtStats *st)
{
    st->exact++;
    int s = ct_sign(h);
    if (s == 2) {
        st->failed = 1;
        return 0;
    }
    return s;
}

/* Exact sign of orient3d(a, b, c, d) by expansions (called when the float filter cannot decide). */
static int
ct_orient3d_exact(const double *a, const double *b, const double *c, const double *d, CtStats *st)
{
    /* two equal points (e.g. a corner shared by coordinates): two equal rows, the determinant is zero */
    const double *p4[4] = {a, b, c, d};
    for (int r = 0; r < 4; r++) {
        for (int s = r + 1; s < 4; s++) {
            if (p4[r][0] == p4[s][0] && p4[r][1] == p4[s][1] && p4[r][2] == p4[s][2]) {
                return 0;
            }
        }
    }
    /* rows as two-term expansions (hi, lo) */
    double hi[3][3], lo[3][3];
    const double *p[3] = {a, b, c};
    for (int r = 0; r < 3; r++) {
        for (int k = 0; k < 3; k++) {
            double x, y;
            ct_two_sum(p[r][k], -d[k], &x, &y);
            hi[r][k] = x;
            lo[r][k] = y;
        }
    }
    static const int terms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 2, 0}, {1, 0, 2}, {2, 0, 1}, {2, 1, 0}};
    static const double signs[6] = {1.0, -1.0, 1.0, -1.0, 1.0, -1.0};
    Expansion h;
    h.n = 0;
    h.overflow = 0;
    for (int t = 0; t < 6; t++) {
        for (int mask = 0; mask < 8; mask++) {
            double x = (mask & 1) ? lo[0][terms[t][0]] : hi[0][terms[t][0]];
            double y = (mask & 2) ? lo[1][terms[t][1]] : hi[1][terms[t][1]];
            double z = (mask & 4) ? lo[2][terms[t][2]] : hi[2][terms[t][2]];
            ct_add_product3(&h, signs[t], x, y, z);
        }
    }
    return ct_exact_sign(&h, st);
}

static int
ct_orient3d(const double *a, const double *b, const double *c, const double *d, CtStats *st)
{
    double ad[3], bd[3], cd[3];
    for (int k = 0; k < 3; k++) {
        ad[k] = a[k] - d[k];
        bd[k] = b[k] - d[k];
        cd[k] = c[k] - d[k];
    }
    double m0 = bd[1] * cd[2] - bd[2] * cd[1];
    double m1 = bd[2] * cd[0] - bd[0] * cd[2];
    double m2 = bd[0] * cd[1] - bd[1] * cd[0];
    double det = ad[0] * m0 + ad[1] * m1 + ad[2] * m2;
    double perm = fabs(ad[0]) * (fabs(bd[1]) * fabs(cd[2]) + fabs(bd[2]) * fabs(cd[1]))
                + fabs(ad[1]) * (fabs(bd[2]) * fabs(cd[0]) + fabs(bd[0]) * fabs(cd[2]))
                + fabs(ad[2]) * (fabs(bd[0]) * fabs(cd[1]) + fabs(bd[1]) * fabs(cd[0]));
    if (perm == 0.0) {
        return 0;
    }
    if (fabs(det) > CONTACT_O3 * perm) {
        return det > 0 ? 1 : -1;
    }
    return ct_orient3d_exact(a, b, c, d, st);
}

/* Exact sign of orient2d(a, b, c) by expansions (called when the float filter cannot decide). */
static int
ct_orient2d_exact(const double *a, const double *b, const double *c, CtStats *st)
{
    if ((a[0] == b[0] && a[1] == b[1]) || (a[0] == c[0] && a[1] == c[1]) || (b[0] == c[0] && b[1] == c[1])) {
        return 0;                       /* two equal points */
    }
    double xh[2], xl[2], yh[2], yl[2];     /* a - c and b - c as (hi, lo) */
    ct_two_sum(a[0], -c[0], &xh[0], &xl[0]);
    ct_two_sum(a[1], -c[1], &xh[1], &xl[1]);
    ct_two_sum(b[0], -c[0], &yh[0], &yl[0]);
    ct_two_sum(b[1], -c[1], &yh[1], &yl[1]);
    Expansion h;
    h.n = 0;
    h.overflow = 0;
    for (int mask = 0; mask < 4; mask++) {
        double p = (mask & 1) ? xl[0] : xh[0];
        double q = (mask & 2) ? yl[1] : yh[1];
        ct_add_product2(&h, 1.0, p, q);
        p = (mask & 1) ? xl[1] : xh[1];
        q = (mask & 2) ? yl[0] : yh[0];
        ct_add_product2(&h, -1.0, p, q);
    }
    return ct_exact_sign(&h, st);
}

static inline int
ct_orient2d(const double *a, const double *b, const double *c, CtStats *st)
{
    double acx = a[0] - c[0], acy = a[1] - c[1], bcx = b[0] - c[0], bcy = b[1] - c[1];
    double left = acx * bcy, right = acy * bcx;
    double det = left - right;
    double perm = fabs(left) + fabs(right);
    if (perm == 0.0) {
        return 0;
    }
    if (fabs(det) > CONTACT_O2 * perm) {
        return det > 0 ? 1 : -1;
    }
    return ct_orient2d_exact(a, b, c, st);
}

enum { CT_NONE = 0, CT_CROSSING = 1, CT_OPPOSITE = 2, CT_CONTACT = 3 };

static int
ct_touch_corner(const int d[3])
{
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        if (d[i] == 0 && d[j] != 0 && d[j] == d[k]) {
            return i;
        }
    }
    return -1;
}

static int
ct_alone_corner(const int d[3])
{
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        if (d[i] != 0 && d[j] * d[i] <= 0 && d[k] * d[i] <= 0) {
            return i;
        }
    }
    return -1;
}

/* x, on the plane of tri, lies in the closed tri; apex is off that plane. */
static int
ct_point_in_triangle(const double *apex, const double *x, const double *const tri[3], CtStats *st)
{
    int s0 = ct_orient3d(apex, x, tri[0], tri[1], st);
    int s1 = ct_orient3d(apex, x, tri[1], tri[2], st);
    int s2 = ct_orient3d(apex, x, tri[2], tri[0], st);
    return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

static const int ct_plane[3][2] = {{1, 2}, {2, 0}, {0, 1}};

static int
ct_coplanar(const double *const t1[3], const double *const t2[3], int axis, const int on1[3], const int on2[3],
            int n_shared, CtStats *st)
{
    double A[3][2], B[3][2];
    for (int i = 0; i < 3; i++) {
        A[i][0] = t1[i][ct_plane[axis][0]];
        A[i][1] = t1[i][ct_plane[axis][1]];
        B[i][0] = t2[i][ct_plane[axis][0]];
        B[i][1] = t2[i][ct_plane[axis][1]];
    }
    int s1 = ct_orient2d(A[0], A[1], A[2], st);
    int s2 = ct_orient2d(B[0], B[1], B[2], st);
    int weak = 0, strict = 0;
    for (int side = 0; side < 2; side++) {
        double (*P)[2] = side ? B : A;
        double (*Q)[2] = side ? A : B;
        int s = side ? s2 : s1;
        for (int e = 0; e < 3; e++) {
            int all_le = 1, all_lt = 1;
            for (int j = 0; j < 3; j++) {
                int o = ct_orient2d(P[e], P[(e + 1) % 3], Q[j], st) * s;
                all_le &= o <= 0;
                all_lt &= o < 0;
            }
            weak |= all_le;
            strict |= all_lt;
        }
    }
    if (!weak) {
        return s1 == s2 ? CT_CROSSING : CT_OPPOSITE;
    }
    if (strict || n_shared >= 2) {
        return CT_NONE;
    }
    if (n_shared == 0) {
        return CT_CONTACT;
    }
    int i1 = on1[0] ? 0 : on1[1] ? 1 : 2;
    int i2 = on2[0] ? 0 : on2[1] ? 1 : 2;
    const double *v = t1[i1];
    for (int x = 1; x <= 2; x++) {
        for (int y = 1; y <= 2; y++) {
            const double *px = t1[(i1 + x) % 3], *py = t2[(i2 + y) % 3];
            if (ct_orient2d(A[i1], A[(i1 + x) % 3], B[(i2 + y) % 3], st) != 0) {
                continue;
            }
            int agree = 1;
            for (int c = 0; c < 3; c++) {
                double u = px[c] - v[c], w = py[c] - v[c];
                agree &= ((u > 0) - (u < 0)) == ((w > 0) - (w < 0));
            }
            if (agree) {
                return CT_CONTACT;
            }
        }
    }
    return CT_NONE;
}

/* ------------------------------------------------------------------------------------------------------
 * One face as the scan reads it, in hierarchy order (neighbours in space are near in memory): its corners,
 * corner indices, and the float normal n = (t1 - t0) x (t2 - t0) with its permanent na (per component,
 * |e1_j||e2_k| + |e1_k||e2_j|).  The side of a point x on the face's plane is then three products:
 * orient3d(t0, t1, t2, x) = -(x - t0) . n, and (x - t0) . n in floats is exactly the float evaluation of
 * ct_orient3d(x, t1, t2, t0) (the same differences, minors, products and sums in the same order), so the
 * same static bound (10 u times the permanent (|x - t0|) . na) decides it, and the exact stage runs when it
 * cannot.
 * ------------------------------------------------------------------------------------------------------ */

typedef struct {
    double t[9];
    double n[3], na[3];
    int64_t fo[3];              /* corner indices */
    int64_t face;               /* index in the caller's faces */
    int32_t axis;               /* projection axis of the coplanar tests (mesh/intersect._face_axes) */
    int16_t skip;               /* zero area: skipped */
    int16_t has_n;              /* n and na computed (ct_face_normal: only when a side test needs them) */
} CtFace;

/* Sign of orient3d(t0, t1, t2, x) for the corners t of face F (the side of x on F's plane) when the float
 * filter decides it, else 2. */
static inline int
ct_side_filter(const CtFace *F, const double *x)
{
    double w0 = x[0] - F->t[0], w1 = x[1] - F->t[1], w2 = x[2] - F->t[2];
    double det = w0 * F->n[0] + w1 * F->n[1] + w2 * F->n[2];
    double perm = fabs(w0) * F->na[0] + fabs(w1) * F->na[1] + fabs(w2) * F->na[2];
    if (perm == 0.0) {
        return 0;
    }
    if (fabs(det) > CONTACT_O3 * perm) {
        return det > 0 ? -1 : 1;
    }
    return 2;
}

/* Sign of orient2d of the projections of a, b, c along axis k (the coordinates ct_plane[k] kept). */
static inline int
ct_orient2d_axis(const double *a, const double *b, const double *c, int k, CtStats *st)
{
    double a2[2] = {a[ct_plane[k][0]], a[ct_plane[k][1]]};
    double b2[2] = {b[ct_plane[k][0]], b[ct_plane[k][1]]};
    double c2[2] = {c[ct_plane[k][0]], c[ct_plane[k][1]]};
    return ct_orient2d(a2, b2, c2, st);
}

/* Faces A, B sharing no, one or two corners by index: 1 when a line (through the shared corner or edge, if
 * any) separates their projections along A's axis, meeting them only in the projection of what they share.
 * A's projection is one to one, so A and B then meet only in what they share: a point of both projects into
 * both projections, i.e. onto the shared corner or edge, whose only preimage in A is itself (and with nothing
 * shared they do not meet).  Exact (orient2d signs); 0 when no such line is found (not a proof of anything). */
static int
ct_projections_separate(const double *const t1[3], const double *const t2[3], const int on1[3],
                        const int on2[3], int n_shared, int k, CtStats *st)
{
    if (n_shared == 2) {
        int r = !on1[0] ? 0 : !on1[1] ? 1 : 2, s = !on2[0] ? 0 : !on2[1] ? 1 : 2;
        const double *p = t1[(r + 1) % 3], *q = t1[(r + 2) % 3];
        int sr = ct_orient2d_axis(p, q, t1[r], k, st);
        int ss = ct_orient2d_axis(p, q, t2[s], k, st);
        return sr * ss < 0;
    }
    if (n_shared == 0) {
        /* disjoint projections: an edge line of one with the other's three corners strictly outside */
        for (int side = 0; side < 2; side++) {
            const double *const *own = side ? t2 : t1, *const *other = side ? t1 : t2;
            for (int e = 0; e < 3; e++) {
                const double *p = own[e], *q = own[(e + 1) % 3];
                int so = ct_orient2d_axis(p, q, own[(e + 2) % 3], k, st);
                if (so == 0) break;               /* B's projection degenerate: no line of it */
                if (ct_orient2d_axis(p, q, other[0], k, st) * so < 0
                    && ct_orient2d_axis(p, q, other[1], k, st) * so < 0
                    && ct_orient2d_axis(p, q, other[2], k, st) * so < 0) {
                    return 1;
                }
            }
        }
        return 0;
    }
    if (n_shared != 1) {
        return 0;
    }
    int i = on1[0] ? 0 : on1[1] ? 1 : 2, j = on2[0] ? 0 : on2[1] ? 1 : 2;
    const double *v = t1[i];
    const double *a[2] = {t1[(i + 1) % 3], t1[(i + 2) % 3]}, *b[2] = {t2[(j + 1) % 3], t2[(j + 2) % 3]};
    for (int side = 0; side < 2; side++) {
        const double *const *own = side ? b : a, *const *other = side ? a : b;
        for (int e = 0; e < 2; e++) {
            /* the line through v and own[e]: own[1 - e] strictly on one side, both of other strictly on the
             * other */
            int so = ct_orient2d_axis(v, own[e], own[1 - e], k, st);
            if (so == 0) continue;
            if (ct_orient2d_axis(v, own[e], other[0], k, st) * so < 0
                && ct_orient2d_axis(v, own[e], other[1], k, st) * so < 0) {
                return 1;
            }
        }
    }
    return 0;
}

/* Fills F's corners from p0, p1, p2 (its normal is computed when first needed, ct_face_normal). */
static inline void
ct_face_geometry(CtFace *F, const double *p0, const double *p1, const double *p2)
{
    for (int c = 0; c < 3; c++) {
        F->t[c] = p0[c];
        F->t[3 + c] = p1[c];
        F->t[6 + c] = p2[c];
    }
    F->has_n = 0;
}

/* F's float normal n = (t1 - t0) x (t2 - t0) and its permanent na, once. */
static inline void
ct_face_normal(CtFace *F)
{
    if (F->has_n) return;
    double e1[3], e2[3];
    for (int c = 0; c < 3; c++) {
        e1[c] = F->t[3 + c] - F->t[c];
        e2[c] = F->t[6 + c] - F->t[c];
    }
    F->has_n = 1;
    F->n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    F->n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    F->n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    F->na[0] = fabs(e1[1]) * fabs(e2[2]) + fabs(e1[2]) * fabs(e2[1]);
    F->na[1] = fabs(e1[2]) * fabs(e2[0]) + fabs(e1[0]) * fabs(e2[2]);
    F->na[2] = fabs(e1[0]) * fabs(e2[1]) + fabs(e1[1]) * fabs(e2[0]);
}

/* Faces A, B sharing no corner or one by index, some corner of A on B's plane undecided by the float filter (the
 * exact stage would be next): 1 when B's corners against A's plane, all decided by the filter, decide the pair
 * without that stage, its kind in *kind; 0 to go on as before.  B strictly on one side of A's plane: they do not
 * meet (NONE).  B on A's plane at one corner x only, its other two corners strictly on one side (a rim corner of
 * a fan-capped cylinder's side wall on the cap's plane): A and B meet at most in x, so with a corner shared by
 * index (x itself, the only corner of B on that plane) only there (NONE), and with none they meet iff x lies in
 * the closed A (CONTACT, else NONE; ct_point_in_triangle, exact).  ct_classify would give the same kinds: a
 * common point lies on B and on A's plane, so it is x; its touch test of A's corner (when A touches B's plane at
 * one corner) finds a common point, hence x in A, and its test of x is this one; A in B's plane would put B's
 * corners on A's plane, and its transversal case needs no corner of B touching alone.  Only the count of exact
 * evaluations is smaller (the corners of A need none). */
static int
ct_touch_first(CtFace *A, const double *const t1[3], const double *const t2[3], const int on2[3], int n_shared,
               CtStats *st, int *kind)
{
    int e2[3];
    ct_face_normal(A);
    for (int j = 0; j < 3; j++) {
        e2[j] = on2[j] ? 0 : ct_side_filter(A, t2[j]);
        if (e2[j] == 2) return 0;
    }
    if ((e2[0] > 0 && e2[1] > 0 && e2[2] > 0) || (e2[0] < 0 && e2[1] < 0 && e2[2] < 0)) {
        *kind = CT_NONE;
        return 1;
    }
    int touch = ct_touch_corner(e2);
    if (touch < 0) return 0;
    if (n_shared > 0) {
        *kind = CT_NONE;
        return 1;
    }
    *kind = ct_point_in_triangle(t2[(touch + 1) % 3], t2[touch], t1, st) ? CT_CONTACT : CT_NONE;
    return 1;
}

/* Kind of the pair of faces A, B (A the lower face index); computes their normals when a side test needs them. */
static int
ct_classify(CtFace *A, CtFace *B, CtStats *st)
{
    const double *t1[3] = {A->t, A->t + 3, A->t + 6}, *t2[3] = {B->t, B->t + 3, B->t + 6};
    int on1[3] = {0, 0, 0}, on2[3] = {0, 0, 0}, n_shared = 0;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            if (A->fo[i] == B->fo[j]) {
                on1[i] = on2[j] = 1;
                n_shared++;
            }
        }
    }
    int d1[3], d2[3];
    int any1 = 0, unsure = 0, separate_tried = 0, kind_early = CT_NONE;
    ct_face_normal(B);
    for (int i = 0; i < 3; i++) {
        d1[i] = on1[i] ? 0 : ct_side_filter(B, t1[i]);
        unsure |= d1[i] == 2;
    }
    /* a sign the filter cannot decide (e.g. adjacent faces in one plane): first try to show without it that
     * the faces meet only in what they share */
    if (unsure && n_shared < 3) {
        separate_tried = 1;
        if (ct_projections_separate(t1, t2, on1, on2, n_shared, A->axis, st)) {
            return CT_NONE;
        }
        if (n_shared < 2 && ct_touch_first(A, t1, t2, on2, n_shared, st, &kind_early)) {
            return kind_early;
        }
    }
    for (int i = 0; i < 3; i++) {
        if (d1[i] == 2) d1[i] = ct_orient3d_exact(B->t, B->t + 3, B->t + 6, t1[i], st);
        any1 |= d1[i] != 0;
    }
    /* sharing an edge: they meet beyond it only when coplanar (the third corner of A on B's plane) */
    if (n_shared >= 2 && any1) {
        return CT_NONE;
    }
    /* A strictly on one side of B's plane */
    if ((d1[0] > 0 && d1[1] > 0 && d1[2] > 0) || (d1[0] < 0 && d1[1] < 0 && d1[2] < 0)) {
        return CT_NONE;
    }
    int touch1 = ct_touch_corner(d1);
    /* sharing one corner, the two others strictly on one side of B's plane: A meets that plane only there */
    if (n_shared == 1 && touch1 >= 0) {
        return CT_NONE;
    }
    /* sharing none, one corner x on B's plane and the two others strictly on one side: A and B meet at most in x,
     * so they meet iff x lies in the closed B, whatever B's corners say of A's plane (the test below would make
     * the same call first, and its other touch test finds a common point only if it is x; see ct_touch_first) */
    if (n_shared == 0 && touch1 >= 0) {
        return ct_point_in_triangle(t1[(touch1 + 1) % 3], t1[touch1], t2, st) ? CT_CONTACT : CT_NONE;
    }
    unsure = 0;
    ct_face_normal(A);
    for (int j = 0; j < 3; j++) {
        d2[j] = on2[j] ? 0 : ct_side_filter(A, t2[j]);
        unsure |= d2[j] == 2;
    }
    if (unsure && n_shared < 3 && !separate_tried
        && ct_projections_separate(t1, t2, on1, on2, n_shared, A->axis, st)) {
        return CT_NONE;
    }
    for (int j = 0; j < 3; j++) {
        if (d2[j] == 2) d2[j] = ct_orient3d_exact(A->t, A->t + 3, A->t + 6, t2[j], st);
    }
    if ((d2[0] > 0 && d2[1] > 0 && d2[2] > 0) || (d2[0] < 0 && d2[1] < 0 && d2[2] < 0)) {
        return CT_NONE;
    }
    if (!any1) {
        return ct_coplanar(t1, t2, A->axis, on1, on2, n_shared, st);
    }
    if (n_shared >= 2) {
        return CT_NONE;
    }
    int touch2 = ct_touch_corner(d2);
    if (touch1 >= 0 || touch2 >= 0) {
        if (n_shared > 0) {
            return CT_NONE;
        }
        if (touch1 >= 0 && ct_point_in_triangle(t1[(touch1 + 1) % 3], t1[touch1], t2, st)) {
            return CT_CONTACT;
        }
        if (touch2 >= 0 && ct_point_in_triangle(t2[(touch2 + 1) % 3], t2[touch2], t1, st)) {
            return CT_CONTACT;
        }
        return CT_NONE;
    }
    /* Guigue and Devillers' canonical form (see mesh/intersect._transversal) */
    int i1 = ct_alone_corner(d1);
    const double *p1 = t1[i1], *q1 = t1[(i1 + 1) % 3], *r1 = t1[(i1 + 2) % 3];
    int order2[3] = {0, 1, 2};
    if (d1[i1] < 0) {
        order2[1] = 2;
        order2[2] = 1;
    }
    const double *t2c[3];
    int d2c[3];
    for (int j = 0; j < 3; j++) {
        t2c[j] = t2[order2[j]];
        d2c[j] = d2[order2[j]];
    }
    int i2 = ct_alone_corner(d2c);
    const double *p2 = t2c[i2], *q2 = t2c[(i2 + 1) % 3], *r2 = t2c[(i2 + 2) % 3];
    if (d2c[i2] < 0) {
        const double *tmp = q1;
        q1 = r1;
        r1 = tmp;
    }
    int low = ct_orient3d(p1, q1, p2, q2, st);
    int high = -ct_orient3d(p1, r1, p2, r2, st);
    int meet = low <= 0 && high <= 0;
    int positive = low < 0 && high < 0;
    int zeros1 = (d1[0] == 0) + (d1[1] == 0) + (d1[2] == 0);
    int zeros2 = (d2[0] == 0) + (d2[1] == 0) + (d2[2] == 0);
    if (positive && zeros1 < 2 && zeros2 < 2) {
        return CT_CROSSING;
    }
    return (n_shared > 0 ? positive : meet) ? CT_CONTACT : CT_NONE;
}

/* ------------------------------------------------------------------------------------------------------
 * contact_scan -- the whole check in one pass: a bounding-volume hierarchy over the face boxes (faces in
 * Morton order of their box centres, sorted by an LSD radix sort; ranges of blocks of CT_LEAF positions halved
 * down to leaves of one block), traversed against itself so that every unordered pair of faces whose closed
 * boxes meet is visited exactly once (each pair of leaves once; a child pair is pushed only when its boxes
 * meet; within a leaf pair a face's box is tested against the other leaf's CT_LEAF boxes at once), each such
 * pair classified on the spot; only the pairs that meet are kept.
 * ------------------------------------------------------------------------------------------------------ */

#ifndef CT_LEAF
#define CT_LEAF 16
#endif
#define CT_MORTON_BITS 11       /* per axis: a 33-bit code, sorted in three passes of 11 bits */

/* Reads at random (faces in hierarchy order, rows of the caller's faces) are fetched this many places ahead. */
#define CT_AHEAD 32

static inline void
ct_prefetch(const void *p)
{
#if defined(__GNUC__) || defined(__clang__)
    __builtin_prefetch(p);
#else
    (void)p;
#endif
}


static inline double
ct_min3(double a, double b, double c)
{
    double m = a < b ? a : b;
    return m < c ? m : c;
}

static inline double
ct_max3(double a, double b, double c)
{
    double m = a > b ? a : b;
    return m > c ? m : c;
}

/* Corner indices of the faces in blocks of CT_LEAF hierarchy positions, corner by corner: block b holds
 * corners 0, 1, 2 of positions CT_LEAF b .. CT_LEAF b + CT_LEAF - 1, CT_LEAF int32 each (ct_share_mask tests
 * one vertex against a whole block); positions past the last face hold -1 (no vertex).  Only the blocks of
 * the leaves a traversal is at are held (CtIdCache), and the one being boxed in pass 3. */
#define CT_IDBLOCK (3 * CT_LEAF)

static inline int32_t
ct_id(const int32_t *ids, int64_t i, int c)      /* corner c of the face at position i */
{
    return ids[CT_IDBLOCK * (i / CT_LEAF) + c * CT_LEAF + i % CT_LEAF];
}

/* The large per-face arrays of contact_scan (issue 25: fresh pages cost the kernel a page fault and a zeroing
 * each, a fifth of the check's CPU time at 1M faces).  Every array of the scan is written before it is read
 * (none relies on zeroed memory: INERTIA_TOOL_CT_POISON fills each block with 0xA5 bytes, for the tests), so
 * a block of CT_SMALL_BYTES or more is, in this order:
 *   1. a block the same call gave back (CtArena: the smallest that fits; the scan's phases never coexist, so
 *      the boxes take the twins' block, the hierarchy's leaf boxes the positions');
 *   2. else a fresh mapping (arena_alloc: the weld's and census's kept mappings unmapped first, then
 *      map_fresh, on 2 MB pages where the kernel offers them); the blocks held meanwhile are the twins' (for
 *      the boxes) under the stars' lists, a few bytes a face, below the traversal's high point.  (Taking the weld's kept mappings instead was tried: a reused block is resident from the
 *      start, while a fresh one only once written, and the analysis's peak rose by 18 MB at 5.24M faces, 32 MB
 *      at 1e7.)
 * The arrays of one size class are asked for in one size (the twins' and boxes' 12 bytes a face, the order's
 * and positions' 4, all padded to whole leaves), so that they fit each other's blocks; sizes
 * are not rounded up to 2 MB, which would make each array's last huge page resident whole (+23 bytes a face at
 * 3e5 faces).  A block reused for a smaller array has its pages past the request given back (MADV_DONTNEED).
 * The sort's words are unmapped when the twins are made (ct_drop: held under the stars' lists they raised the
 * check's high point by 6 bytes a face), and the blocks no array of the traversal takes are unmapped before
 * the boxes are written (ct_arena_trim): the check's high point is that of the phases alone.  Since check7
 * (issue 25: the check set the analysis's peak) the pages of an array whose content is dead until a later
 * phase writes it again are given back meanwhile (ct_drop_pages: the sort words once the order is unpacked,
 * the positions during the patches), the twins are built in rounds over ranges of vertices (ct_twins), the
 * stars' lists are written into the twins' dead block (which the boxes then take) and the traversal keeps no
 * corner indices (CtIdCache).  At the end the blocks go to the pool (ct_arena_release: pool_give_dropped,
 * for the next weld or census in the process).  Below CT_SMALL_BYTES a heap block (malloc;
 * a small part's scan made five mmap/munmap pairs, most of its time: 12-face box 52 -> 11 us; malloc, not
 * calloc: nothing reads before it writes).  ct_free must be given the size ct_alloc returned in *bytes. */
#define CT_SMALL_BYTES ((size_t)1 << 20)
#define CT_ARENA_SLOTS 8

typedef struct {
    void *p[CT_ARENA_SLOTS];            /* blocks given back by this call, NULL for an empty slot */
    size_t bytes[CT_ARENA_SLOTS];
    int poison;                         /* fill every block with 0xA5 bytes (INERTIA_TOOL_CT_POISON, tests) */
    size_t mapped, reused;              /* bytes mapped fresh, taken from the arena */
} CtArena;

/* Unmaps the blocks ar holds (given back by this call and not taken again). */
static void
ct_arena_trim(CtArena *ar)
{
    for (int i = 0; i < CT_ARENA_SLOTS; i++) {
        if (ar->p[i] != NULL) arena_free(ar->p[i], ar->bytes[i]);
        ar->p[i] = NULL;
        ar->bytes[i] = 0;
    }
}

/* At the end of a call: the blocks ar holds go to the pool for the next weld or census in the process
 * (pool_give_dropped, section 2b: from POOL_DROP_BYTES up the mapping is kept but its pages dropped, so that
 * they do not stay resident into the stages after the check; below, kept with its pages, MADV_FREE). */
static void
ct_arena_release(CtArena *ar)
{
    for (int i = 0; i < CT_ARENA_SLOTS; i++) {
        if (ar->p[i] != NULL) pool_give_dropped(ar->p[i], ar->bytes[i]);
        ar->p[i] = NULL;
        ar->bytes[i] = 0;
    }
}

static void *
ct_alloc(CtArena *ar, size_t *bytes)
{
    size_t want = *bytes > 0 ? *bytes : 1;
    void *p = NULL;
    if (want < CT_SMALL_BYTES) {
        p = malloc(want);
        *bytes = want;
    }
    else {
        int best = -1;
        for (int i = 0; i < CT_ARENA_SLOTS; i++) {
            if (ar->p[i] != NULL && ar->bytes[i] >= want && (best < 0 || ar->bytes[i] < ar->bytes[best])) best = i;
        }
        if (best >= 0) {
            p = ar->p[best];
            *bytes = ar->bytes[best];
            ar->p[best] = NULL;
            ar->bytes[best] = 0;
            ar->reused += *bytes;
        }
        else {
            p = arena_alloc(want);                  /* pool_drain, then map_fresh */
            *bytes = want;
            if (p != NULL) ar->mapped += want;
        }
    }
#if defined(__linux__) && defined(MADV_DONTNEED)
    /* a reused block larger than asked: its pages past the request are given back, so that they do not sit
     * resident under the arrays of the phase that takes it (the corner indices in the sort words' block) */
    size_t keep = (want + 4095) & ~(size_t)4095;
    if (p != NULL && want >= CT_SMALL_BYTES && keep < *bytes) {
        madvise((char *)p + keep, *bytes - keep, MADV_DONTNEED);
    }
#endif
    if (p != NULL && ar->poison) memset(p, 0xA5, want);
    return p;
}

/* A block given back for good (not to the arena: no later phase takes it). */
static void
ct_drop(void *p, size_t bytes)
{
    if (bytes < CT_SMALL_BYTES) free(p);
    else arena_free(p, bytes);
}

static void ct_free(CtArena *ar, void *p, size_t bytes);

/* The pages of a mapped block (from CT_SMALL_BYTES up; a heap block is left alone) given back (MADV_DONTNEED):
 * the block stays mapped and reads as zeros, and whatever is written next faults in fresh pages.  For an array
 * whose content is dead until a later phase writes it again, so that it is not resident meanwhile. */
static void
ct_drop_pages(void *p, size_t bytes)
{
#if defined(__linux__) && defined(MADV_DONTNEED)
    if (p != NULL && bytes >= CT_SMALL_BYTES) madvise(p, bytes, MADV_DONTNEED);
#else
    (void)p;
    (void)bytes;
#endif
}

static void
ct_free(CtArena *ar, void *p, size_t bytes)
{
    if (p == NULL) return;
    if (bytes < CT_SMALL_BYTES) {
        free(p);
        return;
    }
    for (int i = 0; i < CT_ARENA_SLOTS; i++) {
        if (ar->p[i] == NULL) {
            ar->p[i] = p;
            ar->bytes[i] = bytes;
            return;
        }
    }
    arena_free(p, bytes);
}

/* The next float32 above a finite f (nextafterf(f, +inf) without the library call): from -0 or +0 the
 * smallest subnormal, else one unit in the last place away from zero for f > 0, toward zero for f < 0;
 * float32's largest finite value goes to +inf. */
static inline float
ct_f32_next_up(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    if ((u & 0x7fffffffu) == 0) {
        u = 1u;
    }
    else if (u >> 31) {
        u--;
    }
    else {
        u++;
    }
    memcpy(&f, &u, sizeof(u));
    return f;
}

/* Boxes in the hierarchy are float32, rounded outward (ct_f32_down / ct_f32_up), so they contain the exact
 * boxes: a pair whose float boxes meet may not be a candidate, and ct_visit decides that from the faces'
 * float64 corners; a pair whose exact boxes meet always has meeting float boxes.  Half the memory of double
 * boxes (24 bytes per face), and half the traffic of the walk. */
static inline float
ct_f32_down(double x)
{
    float f = (float)x;
    return (double)f > x ? -ct_f32_next_up(-f) : f;
}

static inline float
ct_f32_up(double x)
{
    float f = (float)x;
    return (double)f < x ? ct_f32_next_up(f) : f;
}

/* A node of the hierarchy in 32 bytes (two to a cache line): its box, its children or its block, and apex. */
typedef struct {
    float lo[3], hi[3];
    int32_t link;               /* inner: the left child (the right one is link + 1); leaf: -1 - its block */
    int32_t apex;               /* a certified star vertex (ct_stars) of every face below, else -1 */
} CtNode;

/* The root is node 1 (node 0 is unused), so that every left child has an even index and shares its 64-byte
 * line with its sibling (the nodes are page-aligned): a pair of children is one cache line. */
#define CT_ROOT 1
#define CT_IS_LEAF(nd) ((nd)->link < 0)
#define CT_BLOCK_OF(nd) ((int64_t)(-1 - (int64_t)(nd)->link))      /* a leaf's block: positions CT_LEAF b .. */
#define CT_LEFT(nd) ((int64_t)(nd)->link)
#define CT_RIGHT(nd) ((int64_t)(nd)->link + 1)

static inline int
ct_leaf_count(const CtNode *nd, int64_t m)     /* faces in a leaf: its block's, the last one may be short */
{
    int64_t start = CT_LEAF * CT_BLOCK_OF(nd);
    return (int)(m - start < CT_LEAF ? m - start : CT_LEAF);
}

/* Bits 0 .. count - 1: the positions of a leaf's block that hold faces.  A block mask is cut to them: the empty
 * boxes past the last face (lo +inf, hi -inf) meet nothing finite, but a face whose float32 box overflowed to
 * -inf .. +inf (a direct call with coordinates beyond float32's range) would meet them too. */
static inline unsigned
ct_leaf_bits(int count)
{
    return count >= CT_LEAF ? (unsigned)((1ull << CT_LEAF) - 1) : (1u << count) - 1;
}

typedef struct {
    int64_t *a, *b;
    int8_t *kind;
    size_t n, cap;
} CtFound;

static int
ct_found_push(CtFound *fd, int64_t a, int64_t b, int kind)
{
    if (fd->n == fd->cap) {
        size_t cap = fd->cap ? 2 * fd->cap : 256;
        int64_t *na = (int64_t *)realloc(fd->a, cap * sizeof(int64_t));
        if (na == NULL) return -1;
        fd->a = na;
        int64_t *nb = (int64_t *)realloc(fd->b, cap * sizeof(int64_t));
        if (nb == NULL) return -1;
        fd->b = nb;
        int8_t *nk = (int8_t *)realloc(fd->kind, cap);
        if (nk == NULL) return -1;
        fd->kind = nk;
        fd->cap = cap;
    }
    fd->a[fd->n] = a;
    fd->b[fd->n] = b;
    fd->kind[fd->n] = (int8_t)kind;
    fd->n++;
    return 0;
}

/* 21 bits of v spread to every third bit. */
static inline uint64_t
ct_spread(uint64_t v)
{
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}

/* key[i] = code << 31 | i (a 33-bit Morton code above a 31-bit face index) sorted by code, stable (LSD radix
 * sort, three passes of 11 bits over the code, key2 m words of scratch): the face indices in hierarchy order
 * are then key & (2^31 - 1).  One 8-byte word per face moves, not a code and an index.  On one thread: the
 * passes on threads (fixed blocks by ticket, the same order) took ~10 % more CPU and saved no wall time while
 * the other core was busy (docs/performance.md, "Issue 25, hot12").  tests/test_mesh_intersect_sort.py compares it
 * (sort_codes) with a stable sort.  -1 when out of memory. */
static int
ct_radix_sort(uint64_t *key, uint64_t *key2, int64_t m)
{
    size_t (*count)[2048] = (size_t (*)[2048])calloc(3, sizeof(*count));
    if (count == NULL) {
        return -1;
    }
    for (int64_t i = 0; i < m; i++) {
        for (int p = 0; p < 3; p++) count[p][(key[i] >> (31 + 11 * p)) & 2047]++;
    }
    uint64_t *src = key, *dst = key2;
    for (int p = 0; p < 3; p++) {
        size_t sum = 0;
        for (int k = 0; k < 2048; k++) {
            size_t c = count[p][k];
            count[p][k] = sum;
            sum += c;
        }
        for (int64_t i = 0; i < m; i++) {
            dst[count[p][(src[i] >> (31 + 11 * p)) & 2047]++] = src[i];
        }
        uint64_t *t = src; src = dst; dst = t;
    }
    memcpy(key, src, (size_t)m * sizeof(uint64_t));  /* three passes: the result is in key2 */
    free(count);
    return 0;
}

static PyObject *
accel_sort_codes(PyObject *self, PyObject *args)
{
    PyObject *obj;
    if (!PyArg_ParseTuple(args, "O", &obj)) {
        return NULL;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(obj, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        return NULL;
    }
    PyObject *result = NULL;
    char code = native_code(view.format);
    if (view.ndim != 1 || view.itemsize != 8 || (code != 'Q' && code != 'L')) {
        PyErr_SetString(PyExc_ValueError, "Expected `words` as a writable contiguous (m,) uint64 array");
        goto fail;
    }
    int64_t m = (int64_t)view.shape[0];
    uint64_t *scratch = (uint64_t *)malloc((size_t)(m > 0 ? m : 1) * sizeof(uint64_t));
    if (scratch == NULL) {
        PyErr_NoMemory();
        goto fail;
    }
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = ct_radix_sort((uint64_t *)view.buf, scratch, m);
    Py_END_ALLOW_THREADS
    free(scratch);
    if (rc < 0) {
        PyErr_NoMemory();
        goto fail;
    }
    result = Py_None;
    Py_INCREF(result);
fail:
    PyBuffer_Release(&view);
    return result;
}

static int ct_twins(const void *F, int fsize, int64_t n, int64_t m, void *scratch, size_t scratch_bytes,
                    const int32_t *pos, int32_t *twin, int threads, int rounds);
static inline size_t ct_stars_scratch(int64_t n, int64_t m);

/* edge_twins(faces, n_vertices, rounds=1) -> bytes of 3 m int32: the face-pair check's faces across each edge
 * (ct_twins by face, on one thread), for the tests: twin[3 f + c] is the one face running the edge from corner c
 * to corner c + 1 of face f the other way, -1 when no face does, -2 when it is not one. */
static PyObject *
accel_edge_twins(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *fobj;
    Py_ssize_t n_vertices;
    int rounds = 1;
    if (!PyArg_ParseTuple(args, "On|i", &fobj, &n_vertices, &rounds)) {
        return NULL;
    }
    Py_buffer fv;
    Py_ssize_t m;
    int fsize;
    if (get_faces(fobj, &fv, &m, &fsize) < 0) {
        return NULL;
    }
    PyObject *result = NULL;
    if (n_vertices < 0 || n_vertices >= INT32_MAX || m >= INT32_MAX / 3 || rounds < 1 || rounds > 64) {
        PyErr_SetString(PyExc_ValueError, "Expected 0 <= n_vertices < 2**31 - 1, fewer than 2**31 / 3 faces and "
                        "1 <= rounds <= 64");
        goto done;
    }
    int64_t bad = first_bad_index(fv.buf, fsize, 3 * (size_t)m, (int64_t)n_vertices);
    if (bad >= 0) {
        PyErr_Format(PyExc_ValueError, "Expected face indices in 0..%lld, found %lld", (long long)n_vertices - 1,
                     (long long)index_at(fv.buf, fsize, (size_t)bad));
        goto done;
    }
    result = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)(3 * (size_t)m * sizeof(int32_t)));
    if (result == NULL) {
        goto done;
    }
    size_t scratch_bytes = ct_stars_scratch((int64_t)n_vertices, (int64_t)m);
    void *scratch = malloc(scratch_bytes);
    if (scratch == NULL) {
        Py_CLEAR(result);
        PyErr_NoMemory();
        goto done;
    }
    int rc;
    int32_t *twin = (int32_t *)(void *)PyBytes_AS_STRING(result);
    Py_BEGIN_ALLOW_THREADS
    rc = ct_twins(fv.buf, fsize, (int64_t)n_vertices, (int64_t)m, scratch, scratch_bytes, NULL, twin, 1, rounds);
    Py_END_ALLOW_THREADS
    free(scratch);
    if (rc < 0) {
        Py_CLEAR(result);
        PyErr_NoMemory();
    }
done:
    PyBuffer_Release(&fv);
    return result;
}

/* ------------------------------------------------------------------------------------------------------
 * Certified stars (the fan pruning of mesh/intersect.py, see its docstring "Stars").  A vertex v of at least
 * min_faces faces is certified when its faces (v, x, y), with x, y and v distinct, form one edge-connected
 * fan: the link edges x-y make a single path or cycle (every link vertex in at most two of them), with ring
 * r_0 .. r_k (r_k = r_0 for a cycle); and along some coordinate axis every projected triangle (v, r_i,
 * r_{i+1}) has the same strict orientation s (exact orient2d), while the number of steps whose half-open wedge
 * (r_i, r_{i+1}] about v holds the direction of r_0 (s * orient2d(v, r_i, r_0) > 0 and s * orient2d(v, r_0,
 * r_{i+1}) >= 0) is 1 for a cycle and 0 for a path: the projected wedges then turn once round v (cycle) or
 * less than once (path) without overlapping, so two faces of the star meet only in what they share by index,
 * and every pair within the star is of kind "none" without being tested.
 * ------------------------------------------------------------------------------------------------------ */

/* The vertex ids of a large fan or star (section 8: ct_star_certify above CT_STAR_SMALL faces, ct_twin_task
 * above 64), grouped by id in an open-addressing table instead of a comparison sort (qsort with a comparator:
 * on a fan-capped cylinder of 4,800 faces the two 1,200-face caps' sorts were about a tenth of the check).  Each
 * id keeps its count and its first two indices in the order added, which is all either caller reads of a
 * sorted run: the same twins and the same star certificates.  ct_vid_table_make sizes it for k ids (a power
 * of two of at least 2 k slots, so a probe sequence ends within the table), NULL when out of memory. */
typedef struct {
    int32_t key, count;
    int32_t first, second;      /* the first two indices added under key (second -1 until there is one) */
} CtVidSlot;

typedef struct {
    CtVidSlot *slot;
    uint32_t mask;
} CtVidTable;

static int
ct_vid_table_make(CtVidTable *t, int64_t k)
{
    uint64_t size = 16;
    while (size < 2 * (uint64_t)k) size *= 2;
    t->slot = (CtVidSlot *)malloc((size_t)size * sizeof(CtVidSlot));
    if (t->slot == NULL) return -1;
    t->mask = (uint32_t)(size - 1);
    for (uint64_t i = 0; i < size; i++) t->slot[i].count = 0;
    return 0;
}

/* The slot of key: its own, or the empty one where it would go (count 0). */
static inline CtVidSlot *
ct_vid_find(const CtVidTable *t, int32_t key)
{
    uint32_t h = (uint32_t)((uint64_t)(uint32_t)key * 0x9E3779B97F4A7C15ULL >> 32) & t->mask;
    while (t->slot[h].count != 0 && t->slot[h].key != key) h = (h + 1) & t->mask;
    return &t->slot[h];
}

static inline void
ct_vid_add(CtVidTable *t, int32_t key, int32_t index)
{
    CtVidSlot *e = ct_vid_find(t, key);
    if (e->count == 0) {
        e->key = key;
        e->first = index;
        e->second = -1;
    }
    else if (e->count == 1) {
        e->second = index;
    }
    e->count++;
}

/* cert[v]: 0 not certified; CT_STAR_SMALL_CERT certified with fewer than star_faces faces (its pairs are
 * enumerated, counted as candidates and decided by the certificate, not tested one by one: the counts stay
 * those of mesh/intersect.py, which certifies only stars of star_faces faces or more); CT_STAR_BIG certified
 * with star_faces faces or more (its pairs are left out, whole node pairs at a time). */
#define CT_STAR_SMALL_CERT 1
#define CT_STAR_BIG 2
/* Stars of fewer faces are not tried (a pair of faces sharing an edge and nothing else is one "fan" of two
 * faces; three is the smallest star worth certifying). */
#define CT_STAR_MIN 3

/* The ring r_0 .. r_k of the star of v from its k link edges (link[2f], link[2f+1]), walked face to face
 * through shared link vertices; partner[s] is the other slot holding the vertex of slot s (-1: an end).  1 and
 * *closed set when the faces form one edge-connected fan of distinct corners, else 0. */
static int
ct_star_ring(int32_t v, const int32_t *link, int64_t k, const int32_t *partner, int64_t free_slot, int64_t n_free,
             int32_t *ring, int *closed)
{
    for (int64_t s = 0; s < 2 * k; s++) {
        if (link[s] == v) return 0;                        /* a repeated corner */
    }
    for (int64_t f = 0; f < k; f++) {
        if (link[2 * f] == link[2 * f + 1]) return 0;
    }
    if (n_free != 0 && n_free != 2) return 0;
    *closed = n_free == 0;
    int64_t start = *closed ? 0 : free_slot, len = 0, slot = start;
    ring[len++] = link[start];
    for (int64_t steps = 0; steps < k; steps++) {          /* walk face to face through shared link vertices */
        int64_t out = slot ^ 1;                            /* the face's other end */
        ring[len++] = link[out];
        int32_t nx = partner[out];
        if (nx < 0 || nx == start) break;
        slot = nx;
    }
    if (len != k + 1) return 0;                            /* not one fan (several components) */
    if (*closed && ring[k] != ring[0]) return 0;
    return 1;
}

/* 1 when the fan of v with ring r_0 .. r_k turns once (closed) or less than once (open) round v, without
 * overlap, in the projection along some coordinate axis (every projected triangle of one strict orientation). */
static int
ct_star_turns(const double *V, int32_t v, const int32_t *ring, int64_t k, int closed)
{
    for (int axis = 0; axis < 3; axis++) {
        int kx = ct_plane[axis][0], ky = ct_plane[axis][1];
        CtStats st = {0, 0};
        double c[2] = {V[3 * (size_t)v + kx], V[3 * (size_t)v + ky]};
        double r0[2] = {V[3 * (size_t)ring[0] + kx], V[3 * (size_t)ring[0] + ky]};
        int sign = 0, count = 0, good = 1;
        for (int64_t i = 0; i < k && good; i++) {
            double p[2] = {V[3 * (size_t)ring[i] + kx], V[3 * (size_t)ring[i] + ky]};
            double q[2] = {V[3 * (size_t)ring[i + 1] + kx], V[3 * (size_t)ring[i + 1] + ky]};
            int o = ct_orient2d(c, p, q, &st);
            if (o == 0 || (sign != 0 && o != sign)) {
                good = 0;
                break;
            }
            sign = o;
            if (sign * ct_orient2d(c, p, r0, &st) > 0 && sign * ct_orient2d(c, r0, q, &st) >= 0) count++;
        }
        if (good && !st.failed && count == (closed ? 1 : 0)) return 1;
    }
    return 0;
}

/* Stars of at most this many faces are matched on the stack by comparing link vertices pairwise (no sort). */
#define CT_STAR_SMALL 32

/* The ring of a closed fan whose faces are consistently oriented (each link edge (x, y) followed by the one
 * starting at y), the common case of a closed manifold's vertex: 1 and ring r_0 .. r_k (r_k = r_0) when
 * following the link edges from the first one uses each face once, returns to r_0 after the k-th and meets k
 * distinct ring vertices, none v; else 0 (then ct_star_ring decides).  When it returns 1, ct_star_ring finds
 * the same cycle (every ring vertex is in exactly two link edges, no link edge is degenerate), so the
 * certificate (ct_star_turns, invariant under the cycle's starting point and direction) is the same. */
static int
ct_star_ring_oriented(int32_t v, const int32_t *link, int64_t k, int32_t *ring)
{
    if (k < 1) return 0;
    uint64_t used = 1;                                     /* k <= CT_STAR_SMALL <= 64 faces */
    ring[0] = link[0];
    ring[1] = link[1];
    for (int64_t len = 2; len <= k; len++) {
        int32_t at = ring[len - 1];
        int64_t j = 0;
        while (j < k && (((used >> j) & 1u) || link[2 * j] != at)) j++;
        if (j == k) return 0;
        used |= (uint64_t)1 << j;
        ring[len] = link[2 * j + 1];
    }
    if (ring[k] != ring[0]) return 0;
    for (int64_t i = 0; i < k; i++) {
        if (ring[i] == v) return 0;
        for (int64_t j = i + 1; j < k; j++) {
            if (ring[i] == ring[j]) return 0;
        }
    }
    return 1;
}

/* 1 when the star of v (link edges link[0 .. k-1], pairs of vertex ids) is certified, 0 when not, -1 when out
 * of memory. */
static int
ct_star_certify(const double *V, int32_t v, const int32_t *link, int64_t k)
{
    int closed = 0;
    if (k <= CT_STAR_SMALL) {                              /* the common case: everything on the stack */
        int32_t partner[2 * CT_STAR_SMALL], ring[CT_STAR_SMALL + 1];
        if (ct_star_ring_oriented(v, link, k, ring)) {
            return ct_star_turns(V, v, ring, k, 1);
        }
        uint64_t ends[2 * CT_STAR_SMALL];                  /* vertex id << 32 | slot, insertion-sorted */
        int64_t free_slot = -1, n_free = 0;
        for (int64_t s = 0; s < 2 * k; s++) {
            uint64_t key = (uint64_t)(uint32_t)link[s] << 32 | (uint64_t)s;
            int64_t t = s;
            while (t > 0 && ends[t - 1] > key) {
                ends[t] = ends[t - 1];
                t--;
            }
            ends[t] = key;
            partner[s] = -1;
        }
        for (int64_t s = 0; s < 2 * k;) {
            int64_t e = s + 1;
            while (e < 2 * k && ends[e] >> 32 == ends[s] >> 32) e++;
            if (e - s > 2) return 0;                       /* a link vertex in three faces or more */
            if (e - s == 2) {
                partner[ends[s] & 0xffffffffu] = (int32_t)(ends[s + 1] & 0xffffffffu);
                partner[ends[s + 1] & 0xffffffffu] = (int32_t)(ends[s] & 0xffffffffu);
            }
            else {
                n_free++;
                if (free_slot < 0 || (int64_t)(ends[s] & 0xffffffffu) < free_slot) {
                    free_slot = (int64_t)(ends[s] & 0xffffffffu);
                }
            }
            s = e;
        }
        if (!ct_star_ring(v, link, k, partner, free_slot, n_free, ring, &closed)) return 0;
        return ct_star_turns(V, v, ring, k, closed);
    }
    /* the link vertices grouped by id (ct_vid_table): a vertex in two link edges pairs its two slots, one in
     * one is an end of a path, and the walk starts at the end of the smallest id (the first single of the
     * sorted ids that this replaced, so the ring is the same) */
    CtVidTable table = {NULL, 0};
    int32_t *partner = (int32_t *)malloc((size_t)(2 * k) * sizeof(int32_t));
    int32_t *ring = (int32_t *)malloc((size_t)(k + 1) * sizeof(int32_t));
    int ok = 0;
    if (partner == NULL || ring == NULL || ct_vid_table_make(&table, 2 * k) < 0) {
        ok = -1;
        goto done;
    }
    for (int64_t s = 0; s < 2 * k; s++) {
        ct_vid_add(&table, link[s], (int32_t)s);
        partner[s] = -1;
    }
    int64_t free_slot = -1, n_free = 0;
    int32_t free_vid = 0;
    for (uint64_t h = 0; h <= (uint64_t)table.mask; h++) {
        const CtVidSlot *e = &table.slot[h];
        if (e->count == 0) continue;
        if (e->count > 2) goto done;                       /* a link vertex in three faces or more */
        if (e->count == 2) {
            partner[e->first] = e->second;
            partner[e->second] = e->first;
        }
        else {
            n_free++;
            if (free_slot < 0 || e->key < free_vid) {
                free_slot = e->first;
                free_vid = e->key;
            }
        }
    }
    if (ct_star_ring(v, link, k, partner, free_slot, n_free, ring, &closed)) {
        ok = ct_star_turns(V, v, ring, k, closed);
    }
done:
    free(table.slot);
    free(partner);
    free(ring);
    return ok;
}

/* The stars of vertices ranges of ct_stars, certified on threads (each vertex's result is its own). */
typedef struct {
    const double *V;
    const void *F;
    int fsize;
    const int64_t *off;         /* start of each kept vertex's range of faces, -1 for the others */
    const int32_t *faces;       /* the faces holding each kept vertex, vertex after vertex */
    int64_t n, total, min_faces, big_faces;
    uint8_t *cert;
    const int32_t *label;       /* NULL, or per face its certified patch (0: none; ct_patch_labels) */
    int oom[MAX_THREADS];
} CtStarJob;

/* The link edges of v (corners after and before v in each of its k faces) into link (2 k int32). */
static inline void
ct_star_link(const CtStarJob *jb, int32_t v, const int32_t *faces, int64_t k, int32_t *link)
{
    for (int64_t i = 0; i < k; i++) {
        size_t g = 3 * (size_t)faces[i];
        int64_t x0 = index_at(jb->F, jb->fsize, g), x1 = index_at(jb->F, jb->fsize, g + 1);
        int64_t x2 = index_at(jb->F, jb->fsize, g + 2);
        /* v's first corner in the face: a face holding v twice gets a link edge holding v (rejected) */
        int c = x0 == v ? 0 : x1 == v ? 1 : 2;
        int64_t nx = c == 0 ? x1 : c == 1 ? x2 : x0, pv = c == 0 ? x2 : c == 1 ? x0 : x1;
        link[2 * i] = (int32_t)nx;
        link[2 * i + 1] = (int32_t)pv;
    }
}

static void
ct_star_task(void *ctx, int t, int nt)
{
    CtStarJob *jb = (CtStarJob *)ctx;
    int64_t v0 = (int64_t)part_start((size_t)jb->n, t, nt), v1 = (int64_t)part_start((size_t)jb->n, t + 1, nt);
    int64_t v = v0;
    while (v < v1 && jb->off[v] < 0) v++;
    while (v < v1) {
        /* the range ends where the next kept vertex's starts: ranges were laid out in vertex order */
        int64_t w = v + 1;
        while (w < jb->n && jb->off[w] < 0) w++;
        int64_t s = jb->off[v], e = w < jb->n ? jb->off[w] : jb->total;
        if (e - s < jb->min_faces) {                       /* listed for the twins only */
            jb->cert[v] = 0;
            v = w;
            continue;
        }
        if (jb->label != NULL) {
            /* every face of v in one certified patch: no pair of them is enumerated (the patch's node is not
             * paired with itself, and no node pair below it is reached), so v's certificate would decide
             * nothing */
            int32_t l0 = jb->label[jb->faces[s]];
            int64_t i = s + 1;
            while (i < e && jb->label[jb->faces[i]] == l0) i++;
            if (l0 != 0 && i == e) {
                jb->cert[v] = 0;
                v = w;
                continue;
            }
        }
        int32_t link_local[2 * CT_STAR_SMALL];
        int32_t *link = e - s <= CT_STAR_SMALL ? link_local : (int32_t *)malloc((size_t)(2 * (e - s)) * sizeof(int32_t));
        int r = -1;
        if (link != NULL) {
            ct_star_link(jb, (int32_t)v, jb->faces + s, e - s, link);
            r = ct_star_certify(jb->V, (int32_t)v, link, e - s);
            if (link != link_local) free(link);
        }
        if (r < 0) {
            jb->oom[t] = 1;
            return;
        }
        jb->cert[v] = r ? (e - s >= jb->big_faces ? CT_STAR_BIG : CT_STAR_SMALL_CERT) : 0;
        v = w;
    }
}

/* Bytes of scratch ct_stars needs for n vertices and m faces (it takes its arrays from the caller's). */
static inline size_t
ct_stars_scratch(int64_t n, int64_t m)
{
    return (size_t)(n > 0 ? n : 1) * sizeof(int64_t) + 3 * (size_t)(m > 0 ? m : 1) * sizeof(int32_t);
}

/* The faces of each vertex of at least list_min faces (in scratch, ct_stars_scratch(n, m) bytes, any content):
 * *off (n int64: the start of each kept vertex's range of faces, -1 for the others) and *faces (the faces of
 * each kept vertex, vertex after vertex, *total of them; a face holding v twice is listed twice).  With label
 * (per face, its certified patch or 0) a vertex whose faces all lie in one certified patch is not kept either
 * (ct_star_certs would not try it): on a smooth surface that is nearly every vertex, so the lists of the star
 * certificates take a few bytes a face instead of 16 when they are made after the patches.  In two steps
 * (ct_star_count, then ct_star_fill), so that a caller may place the faces once it knows how many there are. */
static int64_t
ct_star_count(int64_t n, const void *F, int fsize, int64_t m, int64_t list_min, const int32_t *label, int64_t *off)
{
    size_t off_bytes = (size_t)(n > 0 ? n : 1) * sizeof(int64_t);
    memset(off, 0, off_bytes);
    if (label == NULL) {
        for (size_t c = 0; c < 3 * (size_t)m; c++) off[index_at(F, fsize, c)]++;
    }
    else {
        /* per vertex, the count of its corners (low 33 bits: at most 3 m < 2^33) and above it its faces' common
         * label, 0 once two differ (0 is also "in no patch": either way the vertex is tried) */
        uint64_t *word = (uint64_t *)off;
        for (int64_t f = 0; f < m; f++) {
            uint64_t l = (uint64_t)(uint32_t)label[f];
            for (int c = 0; c < 3; c++) {
                uint64_t *x = &word[index_at(F, fsize, 3 * (size_t)f + (size_t)c)];
                uint64_t count = *x & ((1ULL << 33) - 1), common = *x >> 33;
                if (count == 0) common = l;
                else if (common != l) common = 0;
                *x = common << 33 | (count + 1);
            }
        }
        for (int64_t v = 0; v < n; v++) {
            off[v] = word[v] >> 33 != 0 ? 0 : (int64_t)(word[v] & ((1ULL << 33) - 1));
        }
    }
    int64_t total = 0;
    for (int64_t v = 0; v < n; v++) {                      /* end of each kept star's range, -1 for the others */
        if (off[v] >= list_min) {
            total += off[v];
            off[v] = total;
        }
        else {
            off[v] = -1;
        }
    }
    return total;
}

/* The lists of ct_star_count's off (then each kept vertex's start) into faces (as many as it returned). */
static void
ct_star_fill(const void *F, int fsize, int64_t m, int64_t *off, int32_t *faces)
{
    for (int64_t f = 0; f < m; f++) {
        for (int c = 0; c < 3; c++) {
            int64_t v = index_at(F, fsize, 3 * (size_t)f + (size_t)c);
            if (off[v] < 0) continue;
            faces[--off[v]] = (int32_t)f;           /* a face holding v twice is listed twice (then rejected) */
        }
    }
}

/* Both steps in scratch (ct_stars_scratch(n, m) bytes, any content): off first, the faces after it. */
static void
ct_star_lists(int64_t n, const void *F, int fsize, int64_t m, int64_t list_min, const int32_t *label, void *scratch,
              int64_t **off_out, int32_t **faces_out, int64_t *total_out)
{
    size_t off_bytes = (size_t)(n > 0 ? n : 1) * sizeof(int64_t);
    int64_t *off = (int64_t *)scratch;
    int32_t *faces = (int32_t *)((char *)scratch + off_bytes);
    int64_t total = ct_star_count(n, F, fsize, m, list_min, label, off);
    ct_star_fill(F, fsize, m, off, faces);
    *off_out = off;
    *faces_out = faces;
    *total_out = total;
}

/* cert[v] <- CT_STAR_BIG for every certified vertex of at least big_faces faces, CT_STAR_SMALL_CERT for every
 * certified one of min_faces .. big_faces - 1, from the lists of ct_star_lists; with label (per face, its
 * certified patch or 0), a vertex whose faces all lie in one certified patch is not tried (cert 0: its
 * certificate would decide no pair).  0, or -1 when out of memory. */
static int
ct_star_certs(const double *V, int64_t n, const void *F, int fsize, const int64_t *off, const int32_t *faces,
              int64_t total, int64_t min_faces, int64_t big_faces, uint8_t *cert, int threads, const int32_t *label)
{
    memset(cert, 0, (size_t)n);
    CtStarJob jb;
    memset(&jb, 0, sizeof(jb));
    jb.V = V;
    jb.F = F;
    jb.fsize = fsize;
    jb.off = off;
    jb.faces = faces;
    jb.n = n;
    jb.total = total;
    jb.min_faces = min_faces;
    jb.big_faces = big_faces;
    jb.cert = cert;
    jb.label = label;
    run_parallel(thread_count(threads, (size_t)n, 20000), ct_star_task, &jb);
    for (int t = 0; t < MAX_THREADS; t++) {
        if (jb.oom[t]) return -1;
    }
    return 0;
}

/* cert as ct_star_certs for every vertex (no patches), the lists in scratch (ct_stars_scratch(n, m) bytes, any
 * content: the memory of the preparation's sort, reused); 0 or -1 when out of memory. */
static int
ct_stars(const double *V, int64_t n, const void *F, int fsize, int64_t m, int64_t min_faces, int64_t big_faces,
         uint8_t *cert, int threads, void *scratch)
{
    int64_t *off, total;
    int32_t *faces;
    ct_star_lists(n, F, fsize, m, min_faces, NULL, scratch, &off, &faces, &total);
    return ct_star_certs(V, n, F, fsize, off, faces, total, min_faces, big_faces, cert, threads, NULL);
}

/* The certified vertex shared by every face at hierarchy positions s .. s+count-1, or -1. */
static int64_t
ct_leaf_apex(const int32_t *ids, const uint8_t *cert, int64_t s, int64_t count)
{
    if (cert == NULL) return -1;
    for (int c = 0; c < 3; c++) {
        int32_t x = ct_id(ids, s, c);
        if (cert[x] != CT_STAR_BIG) continue;
        int all = 1;
        for (int64_t i = s + 1; i < s + count && all; i++) {
            all = ct_id(ids, i, 0) == x || ct_id(ids, i, 1) == x || ct_id(ids, i, 2) == x;
        }
        if (all) return x;
    }
    return -1;
}

/* Boxes of the faces in blocks of CT_LEAF hierarchy positions, coordinate by coordinate (structure of arrays),
 * one 16-bit step number per bound: block b holds lo x, lo y, lo z, hi x, hi y, hi z of positions CT_LEAF b ..
 * CT_LEAF b + CT_LEAF - 1, CT_LEAF CtQ each, on its leaf's grid (ct_grid: the leaf's float32 box cut into
 * CT_QSTEPS steps per axis), rounded outward: 12 bytes a face instead of 24 for float32 boxes.  (Bytes, 254
 * steps, took 6 but tested 75 % more pairs on a CAD part, whose slivers stretch a leaf's box.)  Positions past
 * the last face hold lo CT_QMAX, hi 0, and every block mask is cut to the positions that hold faces
 * (ct_leaf_bits).  One leaf of the
 * hierarchy is one block, so a face is tested against a whole leaf's boxes at once (ct_block_mask).
 *
 * Why the test stays conservative (a pair whose exact boxes meet always passes; the float64 boxes then decide,
 * so the pairs, counts and classes are those of float32 or float64 boxes): on an axis of a leaf with finite
 * float32 bounds L <= H the grid is T(x) = fl(fl(x - L) * inv), inv = fl(S / fl(H - L)), S = CT_QSTEPS (inv = 1 when
 * H = L), a composition of correctly rounded operations with positive constants, hence monotone in x; T(L) = 0
 * and T(H) < S + 1 (S to within a few units in the last place).  A face is stored as floor(T(lo)) and
 * ceil(T(hi)) of its exact (float64) box.  A query box [la, ha] containing another face's exact box gets
 * ql = floor(T(la)) (0 below 0; no face of the leaf meets it when T(la) >= S + 1) and qh = ceil(T(ha)) (S + 1
 * above; none when T(ha) < 0), so exact boxes that meet, lo_b <= hi_a and lo_a <= hi_b, give by monotonicity
 * ql <= T(la) <= T(hi_b) <= qhi_b and qlo_b <= T(lo_b) <= T(ha) <= qh.  A query from another leaf is that
 * face's grid box mapped back (ct_grid_lo / ct_grid_hi: L + q s moved outward by a margin of 2^-48 (|L| + 2^16 s);
 * the map there and back errs by at most about 7 u (|L| + q s), q < 2^16, u = 2^-53: the rounding of T, of
 * s = fl(span fl(1 / S)) against 1 / inv, of q s and of the sum), or a node's float32 box; within one leaf the
 * bytes are compared as they are.  An axis with an infinite bound (coordinates beyond float32's range, a direct
 * call) is not cut: its steps are 0 and CT_QMAX and every query covers them. */
#define CT_BLOCK (6 * CT_LEAF)
typedef uint16_t CtQ;           /* a bound's step number on its leaf's grid */
#define CT_QMAX 65535u
#define CT_QSTEPS 65534.0       /* T(H) < CT_QMAX */

typedef struct {
    double L[3], s[3], inv[3];  /* per axis: the grid's origin, step and inverse step */
    int ok[3];                  /* 0: an infinite bound, every box of the leaf spans the axis */
} CtGrid;

static inline void
ct_grid(const CtNode *leaf, CtGrid *g)
{
    for (int c = 0; c < 3; c++) {
        double lo = leaf->lo[c], hi = leaf->hi[c];
        g->ok[c] = isfinite(lo) && isfinite(hi);
        double span = hi - lo;
        g->L[c] = lo;
        g->s[c] = g->ok[c] && span > 0 ? span * (1.0 / CT_QSTEPS) : 1.0;    /* 1 / inv within a few ulps */
        g->inv[c] = g->ok[c] && span > 0 ? CT_QSTEPS / span : 1.0;
    }
}

/* The stored bytes of the exact bounds lo <= hi on axis c of grid g. */
static inline void
ct_grid_store(const CtGrid *g, int c, double lo, double hi, CtQ *qlo, CtQ *qhi)
{
    if (!g->ok[c]) {
        *qlo = 0;
        *qhi = (CtQ)CT_QMAX;
        return;
    }
    double tl = (lo - g->L[c]) * g->inv[c], th = (hi - g->L[c]) * g->inv[c];     /* 0 <= tl <= th < QMAX */
    unsigned a = tl > 0 ? (unsigned)tl : 0u;                                     /* floor */
    unsigned b = th > 0 ? (unsigned)th : 0u;
    if ((double)b < th) b++;                                                     /* ceil */
    *qlo = (CtQ)(a < CT_QMAX ? a : CT_QMAX);
    *qhi = (CtQ)(b < CT_QMAX ? b : CT_QMAX);
}

/* The query [la, ha] on axis c of grid g as bytes [*ql, *qh]; 0 when it meets no box of the leaf. */
static inline int
ct_grid_query(const CtGrid *g, int c, double la, double ha, unsigned *ql, unsigned *qh)
{
    if (!g->ok[c]) {
        *ql = 0;
        *qh = CT_QMAX;
        return 1;
    }
    double tl = (la - g->L[c]) * g->inv[c], th = (ha - g->L[c]) * g->inv[c];
    if (!(tl < (double)CT_QMAX) || !(th >= 0.0)) return 0;
    unsigned a = tl > 0 ? (unsigned)tl : 0u;
    unsigned b = th < (double)CT_QMAX ? (unsigned)th : CT_QMAX;
    if (th < (double)CT_QMAX && (double)b < th) b++;
    *ql = a;
    *qh = b;
    return 1;
}

/* A stored byte mapped back outward: at most the exact bound it was stored from (lo), at least it (hi). */
static inline double
ct_grid_lo(const CtGrid *g, int c, unsigned q, float node_lo)
{
    if (!g->ok[c]) return node_lo;
    return (g->L[c] + (double)q * g->s[c]) - 0x1p-48 * (fabs(g->L[c]) + 65536.0 * g->s[c]);
}

static inline double
ct_grid_hi(const CtGrid *g, int c, unsigned q, float node_hi)
{
    if (!g->ok[c]) return node_hi;
    return (g->L[c] + (double)q * g->s[c]) + 0x1p-48 * (fabs(g->L[c]) + 65536.0 * g->s[c]);
}

static inline int
ct_ctz(unsigned x)              /* index of the lowest set bit of x != 0 */
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctz(x);
#else
    int k = 0;
    while (!(x & 1u)) {
        x >>= 1;
        k++;
    }
    return k;
#endif
}

/* A face of leaf p as a query on leaf q's grid without mapping each bound back to a coordinate: per axis
 * with both grids cut, t = A + q B with A = fl(fl(L_p - L_q) inv_q), B = fl(s_p inv_q), widened by
 * E = m_p inv_q + 2^-44 (|A| + 2^16 B + 2^16), m_p the margin of ct_grid_lo: in exact arithmetic
 * A + q B - m_p inv_q is (la - L_q) inv_q for the la of ct_grid_lo (at most the face's lower bound), and E also
 * covers the roundings of A, B and of the evaluation (a few u (|A| + 2^16 B)) and T's own (2 u 2^16 on q's
 * range): so floor(A + q_lo B - E) is at most T_q of any bound at or above the face's lower bound, and
 * ceil(A + q_hi B + E) at least T_q of any bound at or below its upper one -- the conditions the monotone
 * argument above asks of ql and qh.  Where q's grid is not cut every face covers the axis; where p's is not,
 * p's node box is the query of every face of p.  0 when no face of p can meet q. */
typedef struct {
    double A[3], B[3], E[3];
    int affine[3];
    unsigned ql[3], qh[3];      /* the query of every face where !affine */
} CtMap;

static inline int
ct_pair_map(const CtGrid *gp, const CtGrid *gq, const CtNode *p, CtMap *map)
{
    int ok = 1;
    for (int c = 0; c < 3; c++) {
        map->affine[c] = 0;
        map->A[c] = map->B[c] = map->E[c] = 0.0;
        map->ql[c] = map->qh[c] = 0;
        if (!gq->ok[c]) {
            map->ql[c] = 0;
            map->qh[c] = CT_QMAX;
        }
        else if (!gp->ok[c]) {
            ok &= ct_grid_query(gq, c, p->lo[c], p->hi[c], &map->ql[c], &map->qh[c]);
        }
        else {
            map->affine[c] = 1;
            map->A[c] = (gp->L[c] - gq->L[c]) * gq->inv[c];
            map->B[c] = gp->s[c] * gq->inv[c];
            map->E[c] = 0x1p-48 * (fabs(gp->L[c]) + 65536.0 * gp->s[c]) * gq->inv[c]
                        + 0x1p-44 * (fabs(map->A[c]) + 65536.0 * map->B[c] + 65536.0);
        }
    }
    return ok;
}

/* Bit j set when box j of the block meets the query steps ql .. qh on every axis (closed boxes). */
static inline unsigned
ct_block_mask(const CtQ *blk, const unsigned *ql, const unsigned *qh)
{
#if defined(__SSE2__) && CT_LEAF == 16
    /* SSE2 compares signed 16-bit words: both sides are moved by 2^15 (x ^ 0x8000), which keeps their order */
    const __m128i flip = _mm_set1_epi16((short)0x8000);
    __m128i bad0 = _mm_setzero_si128(), bad1 = _mm_setzero_si128();    /* positions 0-7, 8-15 */
    for (int c = 0; c < 3; c++) {
        __m128i QH = _mm_xor_si128(_mm_set1_epi16((short)qh[c]), flip);
        __m128i QL = _mm_xor_si128(_mm_set1_epi16((short)ql[c]), flip);
        const __m128i *lo = (const __m128i *)(blk + c * CT_LEAF), *hi = (const __m128i *)(blk + (3 + c) * CT_LEAF);
        /* apart when lo > qh or ql > hi */
        bad0 = _mm_or_si128(bad0, _mm_cmpgt_epi16(_mm_xor_si128(_mm_loadu_si128(lo), flip), QH));
        bad1 = _mm_or_si128(bad1, _mm_cmpgt_epi16(_mm_xor_si128(_mm_loadu_si128(lo + 1), flip), QH));
        bad0 = _mm_or_si128(bad0, _mm_cmpgt_epi16(QL, _mm_xor_si128(_mm_loadu_si128(hi), flip)));
        bad1 = _mm_or_si128(bad1, _mm_cmpgt_epi16(QL, _mm_xor_si128(_mm_loadu_si128(hi + 1), flip)));
    }
    /* one bit per word: pack the two halves' 16-bit masks to bytes (saturation keeps 0 and -1) */
    return ~(unsigned)_mm_movemask_epi8(_mm_packs_epi16(bad0, bad1)) & 0xffffu;
#else
    unsigned mask = 0;
    for (int j = 0; j < CT_LEAF; j++) {
        int meet = 1;
        for (int c = 0; c < 3; c++) {
            meet &= (blk[c * CT_LEAF + j] <= qh[c]) & (ql[c] <= blk[(3 + c) * CT_LEAF + j]);
        }
        mask |= (unsigned)meet << j;
    }
    return mask;
#endif
}

/* The steps of position a of a block as a query on its own leaf's grid. */
static inline void
ct_block_query(const CtQ *blk, int a, unsigned *ql, unsigned *qh)
{
    for (int c = 0; c < 3; c++) {
        ql[c] = blk[c * CT_LEAF + a];
        qh[c] = blk[(3 + c) * CT_LEAF + a];
    }
}

/* Bit j set when vertex x is a corner of the face at position j of the block ids (one CT_IDBLOCK). */
static inline unsigned
ct_share_mask(const int32_t *ids, int32_t x)
{
#if defined(__SSE2__) && CT_LEAF % 4 == 0
    __m128i k = _mm_set1_epi32(x);
    unsigned mask = 0;
    for (int q = 0; q < CT_LEAF / 4; q++) {
        __m128i e = _mm_or_si128(
            _mm_or_si128(_mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(ids + 4 * q)), k),
                         _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(ids + CT_LEAF + 4 * q)), k)),
            _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(ids + 2 * CT_LEAF + 4 * q)), k));
        mask |= (unsigned)_mm_movemask_ps(_mm_castsi128_ps(e)) << (4 * q);
    }
    return mask;
#else
    unsigned mask = 0;
    for (int j = 0; j < CT_LEAF; j++) {
        mask |= (unsigned)((ids[j] == x) | (ids[CT_LEAF + j] == x) | (ids[2 * CT_LEAF + j] == x)) << j;
    }
    return mask;
#endif
}

static inline int
ct_popcount(unsigned x)         /* bits set in x (SWAR: no library call without -mpopcnt) */
{
    uint32_t v = (uint32_t)x;
    v = v - ((v >> 1) & 0x55555555u);
    v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
    v = (v + (v >> 4)) & 0x0f0f0f0fu;
    return (int)((v * 0x01010101u) >> 24);
}

/* The hierarchy's shape: the tree halving block ranges (a leaf is one block of at most CT_LEAF faces), which
 * depends on m alone, so it is built before any box (ct_patches needs only the ranges).  Returns the node
 * count; boxes and apexes are set by ct_build_boxes. */
static int64_t
ct_build_tree(CtNode *nodes, int64_t m)
{
    /* top down, halving block ranges (a parent always precedes its children, which are adjacent); while
     * building, link holds a node's first block and apex its block count */
    int64_t n_nodes = CT_ROOT + 1;
    memset(&nodes[0], 0, sizeof(CtNode));
    nodes[CT_ROOT].link = 0;
    nodes[CT_ROOT].apex = (int32_t)((m + CT_LEAF - 1) / CT_LEAF);
    for (int64_t k = CT_ROOT; k < n_nodes; k++) {
        CtNode *nd = &nodes[k];
        int64_t b0 = nd->link, blocks = nd->apex;
        if (blocks <= 1) {
            nd->link = (int32_t)(-1 - b0);          /* a leaf: one block */
            continue;
        }
        int64_t l = n_nodes++, r = n_nodes++;
        nodes[l].link = (int32_t)b0;
        nodes[l].apex = (int32_t)(blocks / 2);
        nodes[r].link = (int32_t)(b0 + blocks / 2);
        nodes[r].apex = (int32_t)(blocks - blocks / 2);
        nd->link = (int32_t)l;
    }
    return n_nodes;
}

/* The node boxes from the leaves' float32 boxes LBOX (6 floats a block: lo x, y, z, hi x, y, z, the faces'
 * boxes rounded outward, as ct_prep_task computed them before cutting the faces' boxes to steps on them) and
 * the apexes from cert (NULL: none), children before parents, on the tree of ct_build_tree. */
static void
ct_build_boxes(CtNode *nodes, int64_t n_nodes, const float *LBOX, const int32_t *lapex)
{
    for (int64_t k = n_nodes - 1; k >= CT_ROOT; k--) {
        CtNode *nd = &nodes[k];
        if (CT_IS_LEAF(nd)) {
            nd->apex = lapex[CT_BLOCK_OF(nd)];
            const float *lb = LBOX + 6 * CT_BLOCK_OF(nd);
            for (int c = 0; c < 3; c++) {
                nd->lo[c] = lb[c];
                nd->hi[c] = lb[3 + c];
            }
        }
        else {
            const CtNode *p = &nodes[CT_LEFT(nd)], *q = &nodes[CT_RIGHT(nd)];
            nd->apex = p->apex == q->apex ? p->apex : -1;
            for (int c = 0; c < 3; c++) {
                nd->lo[c] = p->lo[c] < q->lo[c] ? p->lo[c] : q->lo[c];
                nd->hi[c] = p->hi[c] > q->hi[c] ? p->hi[c] : q->hi[c];
            }
        }
    }
}

/* ------------------------------------------------------------------------------------------------------
 * Certified patches (mesh/intersect.py, "Patches").  A node of the hierarchy whose faces K satisfy
 *   (a) along some coordinate axis every face projects to a triangle of one strict orientation s (exact
 *       orient2d of its corners in winding order), and
 *   (b) the boundary chain of K (its directed edges, u -> v cancelling v -> u) is a union of cycles whose
 *       projections along that axis are simple polygons meeting only at common vertices without crossing
 *       there, nested only as outline, hole, island ... with orientations s, -s, s ... from the outermost in
 *       (a vertex the chain passes 2 .. 4 times resolved into cycles touching there: ct_pinch_resolve; exact
 *       orient2d throughout),
 * has no two faces meeting beyond what they share by index, so the descent of the node with itself is left
 * out.  Proof (the degree argument behind the normal-cone and contour test of self-collision culling): at a
 * point y of the plane off every projected edge, the number of faces whose projection holds y, times s, is the
 * winding number of the projected boundary chain round y (the faces' boundaries sum to the chain), the sum of
 * the resolved cycles' winding numbers, which for such polygons (the ones holding y nested, alternating in
 * orientation) is 0 or s: the projected faces have disjoint interiors.
 * Then every point of K off the chain has a neighbourhood that projects one to one (the faces round it cover
 * a disk once), so two
 * distinct points of K with one projection both lie on the chain, whose projection is one to one: the
 * projection is one to one on K, and a point common to two faces is one point of K, i.e. in what they share
 * by index.  A node's chain is read off its faces' neighbours across their edges (ct_twins: with the faces in
 * hierarchy order a node is a range of positions, and an edge is on its boundary when the face across it lies
 * outside the range, or there is none); a face with an edge in three faces or more, run twice one way, or at a
 * vertex of fewer than CT_STAR_MIN faces is in no patch.  Nodes whose chain is longer than CT_PATCH_EDGES are
 * not tried (their children are); the simple-polygon sweep stops after a bounded number of segment tests (not
 * certified).  Failing to certify only costs time.
 * ------------------------------------------------------------------------------------------------------ */

#define CT_PATCH_EDGES 2048

typedef struct {
    uint8_t *amask;             /* per node: bit 2 a + (s < 0) when every face has orientation s along axis a */
    /* scratch: an open-addressing table of vertex ids stamped per use (ct_patch_certify) */
    uint64_t *key;
    int32_t *net;
    uint32_t *stamp;
    uint32_t cur;
    int64_t tsize;              /* power of two, at least 4 CT_PATCH_EDGES */
    int oom;
} CtPatchBuild;

static inline uint64_t
ct_edge_hash(uint64_t k)
{
    k ^= k >> 29;
    k *= 0xbf58476d1ce4e5b9ULL;
    k ^= k >> 32;
    return k;
}

/* Twins: for each face f and corner c, the face across its edge from corner c to corner c + 1 (the one face
 * running that edge the other way), -1 when no face does, -2 when it is not one (an edge in three faces or
 * more, run twice one way, a corner held twice, or a vertex whose faces were not listed).  From the faces of
 * each vertex v (ct_stars' lists: off[v] the start of v's range, -1 when v was not kept, ranges in vertex
 * order ending at total): the face across v -> x of f is the face of v's list whose corner before v is x.
 * The lists may be those of a range of vertices only (ct_twins' rounds): off and n then count from the range's
 * first vertex, base.  twin: 3 m int32, all -2 on entry. */
typedef struct {
    const void *F;
    int fsize;
    const int64_t *off;
    const int32_t *faces;
    int64_t n, total;
    int64_t base;               /* the vertex of off[0] */
    const int32_t *pos;         /* NULL, or each face's hierarchy position: twin is then indexed and valued by it */
    int32_t *twin;
    int oom[MAX_THREADS];
} CtTwinJob;

typedef struct {
    int32_t prev, next, face, corner;
} CtLink;

/* twin of face f across the edge from its corner c: by face, or by hierarchy position when jb->pos is given */
static inline void
ct_twin_put(CtTwinJob *jb, int32_t f, int c, int32_t tw)
{
    if (jb->pos != NULL) {
        jb->twin[3 * (size_t)jb->pos[f] + (size_t)c] = tw >= 0 ? jb->pos[tw] : tw;
    }
    else {
        jb->twin[3 * (size_t)f + (size_t)c] = tw;
    }
}

static void
ct_twin_task(void *ctx, int t, int nt)
{
    CtTwinJob *jb = (CtTwinJob *)ctx;
    int64_t v0 = (int64_t)part_start((size_t)jb->n, t, nt), v1 = (int64_t)part_start((size_t)jb->n, t + 1, nt);
    CtLink local[64];
    int64_t v = v0;
    while (v < v1 && jb->off[v] < 0) v++;
    while (v < v1) {
        int64_t w = v + 1;
        while (w < jb->n && jb->off[w] < 0) w++;
        int64_t s = jb->off[v], e = w < jb->n ? jb->off[w] : jb->total, k = e - s;
        /* the rows of the faces listed a vertex or two ahead (about six a vertex), read at random in the caller's
         * faces: fetched now, read when their vertex comes */
        for (int64_t q = e + 6; q < e + 12 && q < jb->total; q++) {
            ct_prefetch((const char *)jb->F + (size_t)jb->fsize * 3 * (size_t)jb->faces[q]);
        }
        CtLink *lk = k <= 64 ? local : (CtLink *)malloc((size_t)k * sizeof(CtLink));
        if (lk == NULL) {
            jb->oom[t] = 1;
            return;
        }
        int ok = 1;
        int64_t vg = v + jb->base;                  /* the vertex, by index */
        for (int64_t i = 0; i < k; i++) {
            int32_t f = jb->faces[s + i];
            int64_t x[3];
            for (int c = 0; c < 3; c++) x[c] = index_at(jb->F, jb->fsize, 3 * (size_t)f + (size_t)c);
            int c = x[0] == vg ? 0 : x[1] == vg ? 1 : 2;
            if ((x[0] == vg) + (x[1] == vg) + (x[2] == vg) != 1) ok = 0;    /* v twice in f: no twins here */
            lk[i].next = (int32_t)x[(c + 1) % 3];
            lk[i].prev = (int32_t)x[(c + 2) % 3];
            lk[i].face = f;
            lk[i].corner = c;
        }
        int32_t first[64];
        uint64_t hit = 0;
        int all = ok && k <= 64;
        for (int64_t i = 0; i < k && all; i++) {
            /* the common case, a closed fan consistently oriented round v: each face's first other face whose
             * corner before v is its corner after v, all distinct (and no face whose corners after and before v
             * are one vertex).  Then every face has exactly one such face and no other face has its corner
             * after v (two faces with one next, or two with one prev, would make two first matches equal),
             * i.e. what the general count below would find */
            if (lk[i].next == lk[i].prev) {
                all = 0;
                break;
            }
            int64_t j = 0;
            while (j < k && (j == i || lk[j].prev != lk[i].next)) j++;
            if (j == k || (hit >> j) & 1u) {
                all = 0;
                break;
            }
            hit |= (uint64_t)1 << j;
            first[i] = (int32_t)j;
        }
        if (all) {
            for (int64_t i = 0; i < k; i++) ct_twin_put(jb, lk[i].face, lk[i].corner, lk[first[i]].face);
        }
        else if (ok && k <= 64) {
            for (int64_t i = 0; i < k; i++) {
                int32_t back = -1, twin = -1, same = 0;
                for (int64_t j = 0; j < k; j++) {
                    if (j == i) continue;
                    if (lk[j].prev == lk[i].next) {
                        back++;
                        twin = lk[j].face;
                    }
                    same += lk[j].next == lk[i].next;
                }
                int32_t tw = back < 0 && !same ? -1 : back == 0 && !same ? twin : -2;
                ct_twin_put(jb, lk[i].face, lk[i].corner, tw);
            }
        }
        else if (ok) {          /* a large fan: the same count as above, by the corners before and after v */
            CtVidTable table, nexts;
            if (ct_vid_table_make(&table, k) < 0) {
                if (lk != local) free(lk);
                jb->oom[t] = 1;
                return;
            }
            if (ct_vid_table_make(&nexts, k) < 0) {
                free(table.slot);
                if (lk != local) free(lk);
                jb->oom[t] = 1;
                return;
            }
            for (int64_t i = 0; i < k; i++) {
                ct_vid_add(&table, lk[i].prev, (int32_t)i);
                ct_vid_add(&nexts, lk[i].next, (int32_t)i);
            }
            for (int64_t i = 0; i < k; i++) {
                const CtVidSlot *e = ct_vid_find(&table, lk[i].next);     /* the faces whose prev is i's next */
                /* back: the others among them (i is one when its corners after and before v are one vertex);
                 * same: the other faces run v -> next one way with i (an edge run twice one way: no twin, as at
                 * 64 faces or fewer, and as the patches' rule says) */
                int32_t back = e->count - (lk[i].prev == lk[i].next);
                int32_t other = e->first != (int32_t)i ? e->first : e->second;
                int32_t same = ct_vid_find(&nexts, lk[i].next)->count - 1;
                int32_t tw = back == 0 && !same ? -1 : back == 1 && !same ? lk[other].face : -2;
                ct_twin_put(jb, lk[i].face, lk[i].corner, tw);
            }
            free(nexts.slot);
            free(table.slot);
        }
        if (lk != local) free(lk);
        v = w;
    }
}

/* 1 when the closed segments p1 q1 and p2 q2 (2-d) meet (exact). */
static int
ct_segments_meet(const double *p1, const double *q1, const double *p2, const double *q2, CtStats *st)
{
    int o1 = ct_orient2d(p1, q1, p2, st), o2 = ct_orient2d(p1, q1, q2, st);
    int o3 = ct_orient2d(p2, q2, p1, st), o4 = ct_orient2d(p2, q2, q1, st);
    if (o1 * o2 < 0 && o3 * o4 < 0) return 1;
#define CT_ON_SEGMENT(a, b, r) ((r)[0] >= ((a)[0] < (b)[0] ? (a)[0] : (b)[0]) \
                                && (r)[0] <= ((a)[0] > (b)[0] ? (a)[0] : (b)[0]) \
                                && (r)[1] >= ((a)[1] < (b)[1] ? (a)[1] : (b)[1]) \
                                && (r)[1] <= ((a)[1] > (b)[1] ? (a)[1] : (b)[1]))
    if (o1 == 0 && CT_ON_SEGMENT(p1, q1, p2)) return 1;
    if (o2 == 0 && CT_ON_SEGMENT(p1, q1, q2)) return 1;
    if (o3 == 0 && CT_ON_SEGMENT(p2, q2, p1)) return 1;
    if (o4 == 0 && CT_ON_SEGMENT(p2, q2, q1)) return 1;
#undef CT_ON_SEGMENT
    return 0;
}

/* 1 when the segments a b and b c (2-d, nonzero lengths) overlap beyond b: collinear, a and c on one side. */
static int
ct_segments_fold(const double *a, const double *b, const double *c, CtStats *st)
{
    if (ct_orient2d(a, b, c, st) != 0) return 0;
    int k = a[0] != b[0] ? 0 : 1;
    return (a[k] > b[k]) == (c[k] > b[k]);
}

typedef struct {
    double lo;
    int32_t i;
} CtSweep;

static int
ct_sweep_cmp(const void *x, const void *y)
{
    const CtSweep *a = (const CtSweep *)x, *b = (const CtSweep *)y;
    return a->lo < b->lo ? -1 : a->lo > b->lo ? 1 : (a->i > b->i) - (a->i < b->i);
}

static inline int
ct_sweep_before(const CtSweep *a, const CtSweep *b)
{
    return a->lo < b->lo || (a->lo == b->lo && a->i < b->i);
}

/* order[0 .. B) sorted by (lo, i), a total order (the indices are distinct), so any correct sort gives this
 * one: runs of 16 by insertion, then merged bottom-up through a buffer of B entries (the comparisons inline:
 * qsort's comparator calls were most of the sort on a fan-capped cylinder's patches); qsort when the buffer
 * cannot be had. */
static void
ct_sweep_sort(CtSweep *order, int64_t B)
{
    for (int64_t s = 0; s < B; s += 16) {
        int64_t e = s + 16 < B ? s + 16 : B;
        for (int64_t x = s + 1; x < e; x++) {
            CtSweep key = order[x];
            int64_t y = x;
            while (y > s && ct_sweep_before(&key, &order[y - 1])) {
                order[y] = order[y - 1];
                y--;
            }
            order[y] = key;
        }
    }
    if (B <= 16) return;
    CtSweep *tmp = (CtSweep *)malloc((size_t)B * sizeof(CtSweep));
    if (tmp == NULL) {
        qsort(order, (size_t)B, sizeof(CtSweep), ct_sweep_cmp);
        return;
    }
    CtSweep *src = order, *dst = tmp;
    for (int64_t w = 16; w < B; w *= 2) {
        for (int64_t s = 0; s < B; s += 2 * w) {
            int64_t m = s + w < B ? s + w : B, e = s + 2 * w < B ? s + 2 * w : B;
            int64_t a = s, b = m, o = s;
            while (a < m && b < e) dst[o++] = ct_sweep_before(&src[b], &src[a]) ? src[b++] : src[a++];
            while (a < m) dst[o++] = src[a++];
            while (b < e) dst[o++] = src[b++];
        }
        CtSweep *t = src;
        src = dst;
        dst = t;
    }
    if (src != order) memcpy(order, src, (size_t)B * sizeof(CtSweep));
    free(tmp);
}

/* 1 when the closed polygons P (2-d points, B of them; the segment of point i runs to point succ[i], every
 * succ cycle of length 3 or more, consecutive points distinct) are simple and pairwise meet only at common
 * vertices: segments meet only where one ends and the next begins (and not folding back along it), two
 * segments of different polygons ending at one vertex by index (edges: the tail and head ids of each segment;
 * a vertex two polygons pass through) only there (not overlapping along a common line), others not at all.
 * A sweep along x tests the pairs whose x and y ranges meet; more than budget segment tests, or an exact
 * stage that overflowed: 0. */
static int
ct_polygons_simple(const double *P, const int32_t *succ, const int32_t *edges, int64_t B, CtSweep *order,
                   int64_t budget, CtStats *st)
{
    for (int64_t i = 0; i < B; i++) {
        const double *a = P + 2 * i, *b = P + 2 * (size_t)succ[i];
        order[i].lo = a[0] < b[0] ? a[0] : b[0];
        order[i].i = (int32_t)i;
    }
    ct_sweep_sort(order, B);
    int64_t tests = 0;
    for (int64_t x = 0; x < B; x++) {
        int64_t i = order[x].i;
        const double *a = P + 2 * i, *b = P + 2 * (size_t)succ[i];
        double hx = a[0] > b[0] ? a[0] : b[0];
        double ly = a[1] < b[1] ? a[1] : b[1], hy = a[1] > b[1] ? a[1] : b[1];
        for (int64_t z = x + 1; z < B && order[z].lo <= hx; z++) {
            int64_t j = order[z].i;
            const double *c = P + 2 * j, *d = P + 2 * (size_t)succ[j];
            if ((c[1] < ly && d[1] < ly) || (c[1] > hy && d[1] > hy)) continue;
            if (++tests > budget) return 0;
            int meet;
            if (succ[i] == j) {                            /* (a, b) then (b, d) */
                meet = ct_segments_fold(a, b, d, st);
            }
            else if (succ[j] == i) {                       /* (c, d) then (d, b) */
                meet = ct_segments_fold(c, d, b, st);
            }
            else {
                int32_t ti = edges[2 * i], hi = edges[2 * i + 1], tj = edges[2 * j], hj = edges[2 * j + 1];
                int shared = (ti == tj) + (ti == hj) + (hi == tj) + (hi == hj);
                if (shared == 1) {                         /* one vertex w by index: they meet beyond it iff */
                    const double *w = ti == tj || ti == hj ? a : b;       /* they overlap along one line */
                    const double *x = w == a ? b : a, *y = tj == ti || tj == hi ? d : c;
                    meet = ct_segments_fold(x, w, y, st);
                }
                else {
                    meet = shared != 0 || ct_segments_meet(a, b, c, d, st);
                }
            }
            if (meet || st->failed) return 0;
        }
    }
    return 1;
}

/* 1 when the point q (2-d) lies inside the closed polygon of points P[i], i = first, succ[first], ... (q on
 * none of its segments): the parity of the segments crossing the ray from q towards +x (exact orient2d). */
static int
ct_point_inside(const double *q, const double *P, const int32_t *succ, int32_t first, int64_t B, CtStats *st)
{
    int inside = 0;
    int32_t i = first;
    for (int64_t steps = 0; steps < B; steps++) {
        const double *a = P + 2 * (size_t)i, *b = P + 2 * (size_t)succ[i];
        if ((a[1] > q[1]) != (b[1] > q[1])) {
            int o = ct_orient2d(a, b, q, st);
            if (b[1] > a[1] ? o > 0 : o < 0) inside ^= 1;
        }
        i = succ[i];
        if (i == first) break;
    }
    return inside;
}

#define CT_PATCH_CYCLES 8       /* boundary cycles of a patch, at most */
#define CT_PINCH_MAX 4          /* boundary passes through one vertex, at most */
#define CT_PINCH_EDGES 256      /* boundary edges entering pinches, at most */

/* Exact angular order about w (2-d) of the directions x - w and y - w (both nonzero): -1 when x comes first
 * counterclockwise from the +x axis (angles in [0, 2 pi)), 1 when y does, 0 when they point the same way. */
static int
ct_angle_cmp(const double *w, const double *x, const double *y, CtStats *st)
{
    int hx = x[1] > w[1] || (x[1] == w[1] && x[0] > w[0]) ? 0 : 1;      /* upper half-plane (angle < pi) */
    int hy = y[1] > w[1] || (y[1] == w[1] && y[0] > w[0]) ? 0 : 1;
    if (hx != hy) return hx < hy ? -1 : 1;
    int o = ct_orient2d(w, x, y, st);                      /* within one half-plane: counterclockwise first */
    return o > 0 ? -1 : o < 0 ? 1 : 0;
}

/* Resolves one pinch vertex w (2-d) of a boundary chain, left by the k >= 2 edges outs[] toward the points
 * head[] and entered by the k edges ins[] from the points tail[]: the 2k directions about w sorted exactly
 * must alternate between leaving and entering, no two the same way; then each entering edge is followed
 * (succ) by the leaving edge next to it on one side, clockwise when side > 0 (across the sectors the faces
 * cover, for s > 0: lobes touching at w), counterclockwise when side < 0 (across the others: a region touching
 * itself round a hole), so the cycles resolved there pass w in disjoint sectors each bounded by two adjacent
 * directions: they touch at w without crossing, whichever side.  0 when not so. */
static int
ct_pinch_resolve(const double *w, const int32_t *outs, const double (*head)[2], const int32_t *ins,
                 const double (*tail)[2], int k, int side, int32_t *succ, CtStats *st)
{
    int32_t dir[2 * CT_PINCH_MAX];              /* a leaving edge e as e, an entering one as -1 - e */
    const double *pt[2 * CT_PINCH_MAX];
    for (int i = 0; i < k; i++) {
        dir[2 * i] = outs[i];
        pt[2 * i] = head[i];
        dir[2 * i + 1] = -1 - ins[i];
        pt[2 * i + 1] = tail[i];
    }
    for (int i = 0; i < 2 * k; i++) {
        if (pt[i][0] == w[0] && pt[i][1] == w[1]) return 0;      /* no direction */
    }
    for (int i = 1; i < 2 * k; i++) {                  /* insertion sort by exact angle */
        int32_t d = dir[i];
        const double *q = pt[i];
        int j = i;
        while (j > 0) {
            int c = ct_angle_cmp(w, pt[j - 1], q, st);
            if (c == 0) return 0;                          /* two edges along one ray: overlapping */
            if (c < 0) break;
            dir[j] = dir[j - 1];
            pt[j] = pt[j - 1];
            j--;
        }
        dir[j] = d;
        pt[j] = q;
    }
    if (st->failed) return 0;
    for (int i = 0; i < 2 * k; i++) {
        if ((dir[i] >= 0) == (dir[(i + 1) % (2 * k)] >= 0)) return 0;       /* not alternating */
    }
    for (int i = 0; i < 2 * k; i++) {
        if (dir[i] >= 0) continue;
        int j = side > 0 ? (i + 2 * k - 1) % (2 * k) : (i + 1) % (2 * k);
        succ[-1 - dir[i]] = dir[j];
    }
    return 1;
}

/* 1 when the chain edges[0 .. B-1] (directed pairs of vertex ids) is, along some axis of amask (every face's
 * projection of one strict orientation s there), a union of at most CT_PATCH_CYCLES cycles whose projections
 * are simple polygons, pairwise meeting only at common vertices, none inside another: a vertex the chain
 * leaves k = 2 .. CT_PINCH_MAX times (a pinch) has its passes resolved by ct_pinch_resolve into cycles that
 * touch there without crossing, each through it once; then no polygon's boundary crosses another's, so any
 * two are apart or one holds the other, which one vertex of each (one the chain leaves once, so on no other
 * polygon) tested against every other tells: the polygons holding a point are nested, and when each
 * polygon's orientation is s under an even number of others and -s under an odd one (an outline, a hole, an
 * island in the hole ...) their winding numbers add up to 0 or s everywhere.  0 otherwise (or out of memory,
 * pb->oom set). */
static int
ct_patch_certify(CtPatchBuild *pb, const double *V, const int32_t *edges, int64_t B, unsigned amask)
{
    if (B < 3 || amask == 0) return 0;
    /* the edges leaving each tail: the table keyed by the tail holds the last listed, nxt chains the others */
    pb->cur++;
    if (pb->cur == 0) {
        memset(pb->stamp, 0, (size_t)pb->tsize * sizeof(uint32_t));
        pb->cur = 1;
    }
    int64_t mask = 15;
    while (mask + 1 < 4 * B && mask + 1 < pb->tsize) mask = 2 * mask + 1;
    int32_t *succ = (int32_t *)malloc((size_t)B * sizeof(int32_t));
    int32_t *nxt = (int32_t *)malloc((size_t)B * sizeof(int32_t));
    int32_t *cyc = (int32_t *)malloc((size_t)B * sizeof(int32_t));
    int32_t *pin = (int32_t *)malloc((size_t)B * sizeof(int32_t));      /* edges entering a pinch */
    int32_t *pin_out = (int32_t *)malloc((size_t)B * sizeof(int32_t));  /* the first edge leaving it */
    uint8_t *twice = (uint8_t *)calloc((size_t)B, 1);                    /* the tail is a pinch */
    double *P = (double *)malloc((size_t)B * 2 * sizeof(double));
    CtSweep *order = (CtSweep *)malloc((size_t)B * sizeof(CtSweep));
    int ok = 0;
    int64_t n_pin = 0;
    if (succ == NULL || nxt == NULL || cyc == NULL || pin == NULL || pin_out == NULL || twice == NULL || P == NULL
        || order == NULL) {
        pb->oom = 1;
        goto done;
    }
    for (int64_t e = 0; e < B; e++) {
        uint64_t k = (uint32_t)edges[2 * e];
        int64_t s = (int64_t)(ct_edge_hash(k) & (uint64_t)mask);
        nxt[e] = -1;
        for (int64_t probe = 0; probe <= mask; probe++) {
            if (pb->stamp[s] != pb->cur) {
                pb->stamp[s] = pb->cur;
                pb->key[s] = k;
                pb->net[s] = (int32_t)e;
                break;
            }
            if (pb->key[s] == k) {                         /* a vertex left twice or more: a pinch */
                nxt[e] = pb->net[s];
                pb->net[s] = (int32_t)e;
                twice[e] = 1;
                twice[nxt[e]] = 1;
                break;
            }
            s = (s + 1) & mask;
        }
    }
    for (int64_t e = 0; e < B; e++) {                      /* succ[e]: the edge leaving e's head */
        uint64_t k = (uint32_t)edges[2 * e + 1];
        int64_t s = (int64_t)(ct_edge_hash(k) & (uint64_t)mask);
        succ[e] = -1;
        for (int64_t probe = 0; probe <= mask; probe++) {
            if (pb->stamp[s] != pb->cur) break;
            if (pb->key[s] == k) {
                succ[e] = pb->net[s];
                break;
            }
            s = (s + 1) & mask;
        }
        if (succ[e] < 0) goto done;                        /* an open chain */
        if (twice[succ[e]]) pin[n_pin++] = (int32_t)e;     /* entering a pinch: resolved per axis */
    }
    if (n_pin > CT_PINCH_EDGES) goto done;                /* many pinches: not tried (the sort below is quadratic) */
    for (int64_t i = 1; i < n_pin; i++) {                  /* the edges entering pinches, by head vertex */
        int32_t x = pin[i];
        int64_t j = i;
        while (j > 0 && edges[2 * pin[j - 1] + 1] > edges[2 * x + 1]) {
            pin[j] = pin[j - 1];
            j--;
        }
        pin[j] = x;
    }
    for (int64_t i = 0; i < n_pin; i++) pin_out[i] = succ[pin[i]];
    for (int attempt = 0; attempt < 6 && !ok; attempt++) {
        /* each axis of amask, with the pinches resolved across the faces' sectors, then (when there are
         * pinches) across the others */
        int axis = attempt >> 1, mode = attempt & 1;
        unsigned bits = (amask >> (2 * axis)) & 3u;
        if (bits != 1u && bits != 2u) continue;
        if (mode == 1 && n_pin == 0) continue;
        int sgn = bits == 1u ? 1 : -1;
        int kx = ct_plane[axis][0], ky = ct_plane[axis][1];
        CtStats st = {0, 0};
        for (int64_t i = 0; i < B; i++) {                  /* point i: the tail of edge i */
            P[2 * i] = V[3 * (size_t)edges[2 * i] + kx];
            P[2 * i + 1] = V[3 * (size_t)edges[2 * i] + ky];
        }
        int good = 1;
        for (int64_t i = 0; i < n_pin && good;) {          /* each pinch: its k entering and k leaving edges */
            int64_t j = i;
            while (j < n_pin && edges[2 * pin[j] + 1] == edges[2 * pin[i] + 1]) j++;
            int32_t outs[CT_PINCH_MAX] = {0}, ins[CT_PINCH_MAX] = {0};
            double head[CT_PINCH_MAX][2], tail[CT_PINCH_MAX][2];
            int k = 0;
            for (int32_t x = pin_out[i]; x >= 0; x = nxt[x]) {
                if (k == CT_PINCH_MAX) {
                    k = -1;
                    break;
                }
                outs[k] = x;
                head[k][0] = V[3 * (size_t)edges[2 * x + 1] + kx];
                head[k][1] = V[3 * (size_t)edges[2 * x + 1] + ky];
                k++;
            }
            if (k < 2 || k != j - i) {
                good = 0;
                break;
            }
            for (int64_t x = i; x < j; x++) {
                ins[x - i] = pin[x];
                tail[x - i][0] = P[2 * (size_t)pin[x]];
                tail[x - i][1] = P[2 * (size_t)pin[x] + 1];
            }
            good = ct_pinch_resolve(P + 2 * (size_t)outs[0], outs, (const double (*)[2])head, ins,
                                    (const double (*)[2])tail, k, mode == 0 ? sgn : -sgn, succ, &st);
            i = j;
        }
        if (!good || st.failed) continue;
        /* every edge on one cycle (succ a permutation), at most CT_PATCH_CYCLES of them */
        int32_t first[CT_PATCH_CYCLES];
        int n_cycles = 0;
        for (int64_t e = 0; e < B; e++) cyc[e] = -1;
        for (int64_t e = 0; e < B && good; e++) {
            if (cyc[e] >= 0) continue;
            if (n_cycles == CT_PATCH_CYCLES) {
                good = 0;
                break;
            }
            first[n_cycles] = (int32_t)e;
            int64_t x = e, steps = 0;
            do {
                if (cyc[x] >= 0) {                         /* joins a cycle already walked: not disjoint */
                    good = 0;
                    break;
                }
                cyc[x] = n_cycles;
                x = succ[x];
                steps++;
            } while (x != e && steps <= B);
            if (good && x != e) good = 0;
            n_cycles++;
        }
        for (int64_t i = 0; i < n_pin && good; i++) {      /* each cycle through a pinch once */
            for (int32_t x = pin_out[i]; x >= 0 && good; x = nxt[x]) {
                for (int32_t y = nxt[x]; y >= 0 && good; y = nxt[y]) {
                    if (cyc[x] == cyc[y]) good = 0;
                }
            }
        }
        if (!good) continue;
        int ax = ct_polygons_simple(P, succ, edges, B, order, 64 * B + 4096, &st);
        for (int c = 0; c < n_cycles && ax && n_cycles > 1; c++) {
            /* c's depth (the cycles holding it, tested at a vertex of c on no other) and orientation (the
             * turn at its lowest-leftmost vertex, strict for a simple polygon) must alternate s, -s, ...
             * from the outermost in: then the winding numbers add up to 0 or s everywhere */
            int64_t q = first[c], steps = 0;
            while (twice[q] && steps < B) {                /* a vertex of c on no other cycle */
                q = succ[q];
                steps++;
            }
            if (twice[q]) {
                ax = 0;
                break;
            }
            int depth = 0;
            for (int d = 0; d < n_cycles; d++) {
                if (d != c && ct_point_inside(P + 2 * (size_t)q, P, succ, first[d], B, &st)) depth++;
            }
            int64_t low = first[c], prev = -1, x = first[c];
            steps = 0;
            do {                                           /* the lowest-leftmost vertex and the edge into it */
                int64_t y = succ[x];
                const double *py = P + 2 * (size_t)y, *pl = P + 2 * (size_t)low;
                if (py[0] < pl[0] || (py[0] == pl[0] && py[1] < pl[1])) {
                    low = y;
                    prev = x;
                }
                x = y;
                steps++;
            } while (x != first[c] && steps <= B);
            if (prev < 0) {                                /* first[c] itself: the edge into it */
                prev = first[c];
                while (succ[prev] != first[c] && steps <= 2 * B) {
                    prev = succ[prev];
                    steps++;
                }
            }
            int turn = ct_orient2d(P + 2 * (size_t)prev, P + 2 * (size_t)low, P + 2 * (size_t)succ[low], &st);
            if (turn == 0 || turn != ((depth & 1) ? -sgn : sgn)) ax = 0;
        }
        if (st.failed) ax = 0;
        ok = ax;
    }
done:
    free(succ);
    free(nxt);
    free(cyc);
    free(pin);
    free(pin_out);
    free(twice);
    free(P);
    free(order);
    return ok;
}

/* Meshes of at least this many faces build the twins in CT_TWIN_ROUNDS rounds (ct_twins), smaller ones in one;
 * INERTIA_TOOL_CT_TWIN_ROUNDS (1 .. 64) sets the count for every mesh (the tests). */
#define CT_TWIN_ROUNDS_FACES ((int64_t)1 << 19)
#define CT_TWIN_ROUNDS 4

static int
ct_twin_rounds(int64_t m)
{
    const char *env = getenv("INERTIA_TOOL_CT_TWIN_ROUNDS");
    if (env != NULL && *env) {
        long r = strtol(env, NULL, 10);
        if (r >= 1 && r <= 64) return (int)r;
    }
    return m >= CT_TWIN_ROUNDS_FACES ? CT_TWIN_ROUNDS : 1;
}

/* twin (3 m int32, by hierarchy position when pos is given) from the faces of every vertex, in rounds: the
 * vertices are cut into `rounds` ranges of equal count, and for each range the faces of its vertices are listed
 * in scratch (as ct_star_lists lists them for list_min 1: off per vertex of the range, -1 for one of no face,
 * then the faces, each vertex's in decreasing face order) and ct_twin_task run over them.  A face's corner c is
 * written in the round of its vertex at c and in no other, so the twins are those of one round over every
 * vertex; the lists take about 1 / rounds of the 8 n + 12 m bytes of one round (issue 25: the lists and the
 * twins set the check's high point).  The faces are read rounds + 1 times: once for the first round's counts,
 * then once a round, which lists its faces and counts the next round's (8 bytes a vertex of a range, apart).  scratch: at least ct_stars_scratch(n,
 * m) bytes, any content; a mapped one (CT_SMALL_BYTES or more) has its pages given back (MADV_DONTNEED) first
 * and past each round's lists after its count.  0, or -1 when out of memory. */
static int
ct_twins(const void *F, int fsize, int64_t n, int64_t m, void *scratch, size_t scratch_bytes, const int32_t *pos,
         int32_t *twin, int threads, int rounds)
{
    /* scratch's pages given back before the twins are written, not after each round's count: else the twins
     * and the whole of scratch would be resident together */
    ct_drop_pages(scratch, scratch_bytes);
    for (size_t i = 0; i < 3 * (size_t)m; i++) twin[i] = -2;
    if (rounds < 1) rounds = 1;
    if ((int64_t)rounds > n) rounds = n > 0 ? (int)n : 1;
    /* the next round's counts, made by this round's pass over the faces (each round after the first costs one
     * pass, not two); a range holds at most ceil(n / rounds) vertices */
    size_t next_bytes = rounds > 1 ? (size_t)((n + rounds - 1) / rounds) * sizeof(int64_t) : 0;
    int64_t *next = rounds > 1 ? (int64_t *)malloc(next_bytes) : NULL;
    if (rounds > 1 && next == NULL) return -1;
    int64_t *off = (int64_t *)scratch;
    int64_t n0 = (int64_t)part_start((size_t)n, 1, rounds);
    memset(off, 0, (size_t)(n0 > 0 ? n0 : 1) * sizeof(int64_t));
    for (size_t c = 0; c < 3 * (size_t)m; c++) {           /* the first round's counts */
        uint64_t v = (uint64_t)index_at(F, fsize, c);
        if (v < (uint64_t)n0) off[v]++;
    }
    int rc = 0;
    for (int r = 0; r < rounds && rc == 0; r++) {
        int64_t va = (int64_t)part_start((size_t)n, r, rounds), vb = (int64_t)part_start((size_t)n, r + 1, rounds);
        int64_t nv = vb - va;
        int64_t vc = r + 1 < rounds ? (int64_t)part_start((size_t)n, r + 2, rounds) : vb;   /* next: vb .. vc */
        int32_t *faces = (int32_t *)((char *)scratch + (size_t)(nv > 0 ? nv : 1) * sizeof(int64_t));
        if (r > 0) memcpy(off, next, (size_t)nv * sizeof(int64_t));
        int64_t total = 0;
        for (int64_t v = 0; v < nv; v++) {          /* end of each listed vertex's range, -1 for one of no face */
            if (off[v] >= 1) {
                total += off[v];
                off[v] = total;
            }
            else {
                off[v] = -1;
            }
        }
#if defined(__linux__) && defined(MADV_DONTNEED)
        if (scratch_bytes >= CT_SMALL_BYTES) {
            size_t keep = ((size_t)nv * sizeof(int64_t) + (size_t)total * sizeof(int32_t) + 4095) & ~(size_t)4095;
            if (keep < scratch_bytes) madvise((char *)scratch + keep, scratch_bytes - keep, MADV_DONTNEED);
        }
#else
        (void)scratch_bytes;
#endif
        if (vc > vb) memset(next, 0, (size_t)(vc - vb) * sizeof(int64_t));
        for (int64_t f = 0; f < m; f++) {
            for (int c = 0; c < 3; c++) {
                int64_t x = index_at(F, fsize, 3 * (size_t)f + (size_t)c);
                uint64_t v = (uint64_t)(x - va);
                if (v < (uint64_t)nv) {
                    if (off[v] >= 0) faces[--off[v]] = (int32_t)f;
                }
                else if ((uint64_t)(x - vb) < (uint64_t)(vc - vb)) {
                    next[x - vb]++;
                }
            }
        }
        CtTwinJob jb;
        memset(&jb, 0, sizeof(jb));
        jb.F = F;
        jb.fsize = fsize;
        jb.off = off;
        jb.faces = faces;
        jb.n = nv;
        jb.total = total;
        jb.base = va;
        jb.pos = pos;
        jb.twin = twin;
        run_parallel(thread_count(threads, (size_t)nv, 20000), ct_twin_task, &jb);
        for (int t = 0; t < MAX_THREADS; t++) {
            if (jb.oom[t]) rc = -1;
        }
    }
    free(next);
    return rc;
}

/* patch[k] <- 1 for the highest nodes certified as above (their descendants are not tried).  fmask: per
 * hierarchy position, bit 2 a + (s < 0) when the face's projection along axis a has strict orientation s (0
 * for a face in no patch); across: per position and corner, the position of the face across the edge from
 * that corner to the next, or -1 (none); the corners read from the faces F through order (the face at each
 * position), as the hierarchy's boxes and corner indices do not exist yet.  0, or -1 when out of memory. */
static int
ct_patches(const CtNode *nodes, int64_t n_nodes, const void *F, int fsize, const int32_t *order, const uint8_t *fmask,
           const int32_t *across, const double *V, int64_t m, uint8_t *patch)
{
    CtPatchBuild pb;
    memset(&pb, 0, sizeof(pb));
    memset(patch, 0, (size_t)n_nodes);
    pb.tsize = 1;
    while (pb.tsize < 4 * CT_PATCH_EDGES) pb.tsize *= 2;
    pb.amask = (uint8_t *)malloc((size_t)n_nodes);
    pb.key = (uint64_t *)malloc((size_t)pb.tsize * sizeof(uint64_t));
    pb.net = (int32_t *)malloc((size_t)pb.tsize * sizeof(int32_t));
    pb.stamp = (uint32_t *)calloc((size_t)pb.tsize, sizeof(uint32_t));
    int32_t *pairs = (int32_t *)malloc((size_t)(CT_PATCH_EDGES + 1) * 2 * sizeof(int32_t));
    int64_t *stack = (int64_t *)malloc((size_t)(n_nodes + 1) * sizeof(int64_t));
    int64_t *first = (int64_t *)malloc((size_t)n_nodes * sizeof(int64_t));     /* positions of each node */
    int64_t *last = (int64_t *)malloc((size_t)n_nodes * sizeof(int64_t));
    int rc = 0;
    if (pb.amask == NULL || pb.key == NULL || pb.net == NULL || pb.stamp == NULL || pairs == NULL || stack == NULL
        || first == NULL || last == NULL) {
        rc = -1;
        goto done;
    }
    pb.cur = 0;
    for (int64_t k = n_nodes - 1; k >= CT_ROOT; k--) {    /* children before parents */
        const CtNode *nd = &nodes[k];
        if (CT_IS_LEAF(nd)) {
            int64_t start = CT_LEAF * CT_BLOCK_OF(nd), count = ct_leaf_count(nd, m);
            unsigned am = 63u;
            for (int64_t i = start; i < start + count; i++) am &= fmask[i];
            pb.amask[k] = (uint8_t)am;
            first[k] = start;
            last[k] = start + count;
        }
        else {
            pb.amask[k] = pb.amask[CT_LEFT(nd)] & pb.amask[CT_RIGHT(nd)];
            first[k] = first[CT_LEFT(nd)];
            last[k] = last[CT_RIGHT(nd)];
        }
    }
    {
        int64_t top = 0;                                   /* top down: the highest certified nodes */
        stack[top++] = CT_ROOT;
        while (top > 0) {
            int64_t k = stack[--top];
            const CtNode *nd = &nodes[k];
            if (pb.amask[k] != 0) {
                /* the chain: the edges whose face across lies outside the node's positions, or is none */
                int64_t s = first[k], e = last[k], B = 0;
                for (int64_t i = s; i < e && B <= CT_PATCH_EDGES; i++) {
                    for (int c = 0; c < 3; c++) {
                        int32_t t = across[3 * (size_t)i + (size_t)c];
                        if (t >= s && t < e) continue;
                        if (B == CT_PATCH_EDGES) {
                            B++;
                            break;
                        }
                        size_t row = 3 * (size_t)order[i];
                        pairs[2 * B] = (int32_t)index_at(F, fsize, row + (size_t)c);
                        pairs[2 * B + 1] = (int32_t)index_at(F, fsize, row + (size_t)((c + 1) % 3));
                        B++;
                    }
                }
                if (B <= CT_PATCH_EDGES && ct_patch_certify(&pb, V, pairs, B, pb.amask[k])) {
                    patch[k] = 1;
                    continue;
                }
                if (pb.oom) {
                    rc = -1;
                    break;
                }
            }
            if (!CT_IS_LEAF(nd)) {
                stack[top++] = CT_LEFT(nd);
                stack[top++] = CT_RIGHT(nd);
            }
        }
    }
done:
    free(pb.amask);
    free(pb.key);
    free(pb.net);
    free(pb.stamp);
    free(pairs);
    free(stack);
    free(first);
    free(last);
    return rc;
}

/* label[f] <- the certified patch (its node) holding face f, 0 for a face in none; order: the face at each
 * hierarchy position.  Top down; the stack holds at most one node per level and one more (depth <= 32: the
 * tree halves ranges of fewer than 2^31 blocks). */
static void
ct_patch_labels(const CtNode *nodes, const uint8_t *patch, const int32_t *order, int64_t m, int32_t *label)
{
    int64_t stack[2 * 80];
    int top = 0;
    stack[0] = CT_ROOT;
    stack[1] = 0;
    top = 1;
    while (top > 0) {
        top--;
        int64_t k = stack[2 * top], lab = stack[2 * top + 1];
        const CtNode *nd = &nodes[k];
        if (lab == 0 && patch[k]) lab = k;
        if (CT_IS_LEAF(nd)) {
            int64_t start = CT_LEAF * CT_BLOCK_OF(nd), count = ct_leaf_count(nd, m);
            for (int64_t i = start; i < start + count; i++) label[order[i]] = (int32_t)lab;
            continue;
        }
        stack[2 * top] = CT_LEFT(nd);
        stack[2 * top + 1] = lab;
        top++;
        stack[2 * top] = CT_RIGHT(nd);
        stack[2 * top + 1] = lab;
        top++;
    }
}

typedef struct {
    const CtQ *BOX;             /* face boxes as steps on their leaf's grid, in blocks of CT_LEAF (ct_block_mask) */
    const int32_t *order;       /* the caller's face index of each hierarchy position */
    const void *F;              /* the caller's faces (m, 3), int32 or int64 (fsize bytes an index) */
    int fsize;
    const uint8_t *flags;       /* projection axis | zero area << 2, in hierarchy order */
    const double *V;            /* vertices (n, 3) */
    const CtNode *nodes;
    int64_t m;                  /* faces */
    const uint8_t *stars;       /* certified corners per position (ct_visit), NULL without pruning */
    const uint8_t *patch;       /* certified patches per node (ct_patches), NULL without them */
    long long max_pairs;        /* < 0: no bound */
    long long candidates, tested;
    long exact;
    int complete, oom;
    CtFound found;
    long long node_pairs, leaf_pairs, loads;   /* work counts, printed with INERTIA_TOOL_CT_PROFILE */
} CtScan;

/* The corner indices of one leaf's block of CT_LEAF hierarchy positions (the layout of ct_id: corner by corner,
 * -1 past the last face), read from the caller's faces through order when the traversal first needs them
 * (ct_leaf_ids).  They are not kept for every face (12 bytes a face, a third of the check's high point at the
 * traversal): each traversal keeps those of the two leaves it is at, so a leaf recurring in consecutive leaf
 * pairs is read once. */
typedef struct {
    int64_t block;              /* the leaf's block, -1 for none */
    int filled;                 /* id holds that block's corner indices */
    int32_t id[CT_IDBLOCK];
} CtIdCache;

static inline void
ct_id_cache_at(CtIdCache *c, int64_t block)
{
    if (c->block != block) {
        c->block = block;
        c->filled = 0;
    }
}

static const int32_t *
ct_leaf_ids(const CtScan *sc, CtIdCache *c)
{
    if (!c->filled) {
        int64_t start = CT_LEAF * c->block;
        int count = (int)(sc->m - start < CT_LEAF ? sc->m - start : CT_LEAF);
        for (int j = 0; j < count; j++) {       /* the rows lie at random in the caller's faces: all fetched first */
            ct_prefetch((const char *)sc->F + (size_t)sc->fsize * 3 * (size_t)sc->order[start + j]);
        }
        for (int j = 0; j < CT_LEAF; j++) {
            size_t g = j < count ? 3 * (size_t)sc->order[start + j] : 0;
            for (int k = 0; k < 3; k++) {
                c->id[k * CT_LEAF + j] = j < count ? (int32_t)index_at(sc->F, sc->fsize, g + (size_t)k) : -1;
            }
        }
        c->filled = 1;
    }
    return c->id;
}

/* The face at hierarchy position i as ct_classify reads it: its corners, normal and the normal's permanent
 * (the arithmetic of ct_face_normal, when first needed), its corner indices (from ci, the cache of its leaf's
 * block), and the axis and zero-area flag ct_prep_task gave it in the preparation.  No per-face record of 160
 * bytes is kept: a face is rebuilt from the vertices when a box meets its. */
static inline void
ct_face_load(CtFace *F, const CtScan *sc, int64_t i, CtIdCache *ci)
{
    const int32_t *ids = ct_leaf_ids(sc, ci);
    for (int k = 0; k < 3; k++) {
        F->fo[k] = ct_id(ids, i % CT_LEAF, k);
    }
    ct_face_geometry(F, sc->V + 3 * (size_t)F->fo[0], sc->V + 3 * (size_t)F->fo[1], sc->V + 3 * (size_t)F->fo[2]);
    F->face = sc->order[i];
    F->axis = sc->flags[i] & 3;
    F->skip = sc->flags[i] >> 2;
}

/* A pair of faces (hierarchy positions i, j) whose float32 boxes meet and that share no certified star vertex:
 * the float64 boxes, then the test; returns 0 to go on, 1 to stop (bound reached or out of memory). */
static int
ct_test_pair(CtScan *sc, int64_t i, int64_t j, CtFace *FI, uint8_t *have_i, CtFace *FJ, uint8_t *have_j,
             CtIdCache *ci, CtIdCache *cj)
{
    sc->loads++;
    if (!*have_i) {                         /* each face of a leaf pair is loaded once, when first needed */
        ct_face_load(FI, sc, i, ci);
        *have_i = 1;
    }
    if (!*have_j) {
        ct_face_load(FJ, sc, j, cj);
        *have_j = 1;
    }
    for (int c = 0; c < 3; c++) {           /* the exact (float64) boxes */
        if (ct_max3(FI->t[c], FI->t[3 + c], FI->t[6 + c]) < ct_min3(FJ->t[c], FJ->t[3 + c], FJ->t[6 + c])
            || ct_max3(FJ->t[c], FJ->t[3 + c], FJ->t[6 + c]) < ct_min3(FI->t[c], FI->t[3 + c], FI->t[6 + c])) {
            return 0;
        }
    }
    if (sc->max_pairs >= 0 && sc->candidates >= sc->max_pairs) {
        sc->complete = 0;
        return 1;
    }
    sc->candidates++;
    if (FI->skip || FJ->skip) return 0;
    sc->tested++;
    CtFace *A = FI, *B = FJ;
    if (A->face > B->face) {
        CtFace *T = A;
        A = B;
        B = T;
    }
    CtStats st = {0, 0};
    int kind = ct_classify(A, B, &st);
    sc->exact += st.exact;
    if (st.failed) kind = -1;
    if (kind != CT_NONE && ct_found_push(&sc->found, A->face, B->face, kind) < 0) {
        sc->oom = 1;
        return 1;
    }
    return 0;
}

/* A pair of faces (hierarchy positions i, j) whose float32 boxes meet; returns 0 to go on, 1 to stop (bound
 * reached or out of memory).  Two faces of one certified star meet only in what they share (ct_stars): a
 * big star's pair is left out (not a candidate on either twin); a small star's is a candidate (the closed
 * boxes share the vertex) of two faces of nonzero area (each projects to a triangle of nonzero area), decided
 * "none" by the certificate and counted as tested, without rebuilding either face.  stars[i] says which
 * corners of the face at position i are certified (bit c: small star, bit 3 + c: big star). */
static inline int
ct_visit(CtScan *sc, int64_t i, int64_t j, CtFace *FI, uint8_t *have_i, CtFace *FJ, uint8_t *have_j,
         CtIdCache *ci, CtIdCache *cj)
{
    unsigned bits = sc->stars != NULL ? sc->stars[i] : 0;
    if (bits) {
        const int32_t *jd = ct_leaf_ids(sc, cj), *id = ct_leaf_ids(sc, ci);
        int64_t jj = j % CT_LEAF, ii = i % CT_LEAF;
        int32_t y0 = ct_id(jd, jj, 0), y1 = ct_id(jd, jj, 1), y2 = ct_id(jd, jj, 2);
        unsigned shared = 0;                /* bit c: corner c of face i is a corner of face j */
        for (int c = 0; c < 3; c++) {
            int32_t x = ct_id(id, ii, c);
            shared |= (unsigned)((x == y0) | (x == y1) | (x == y2)) << c;
        }
        if ((bits >> 3) & shared) return 0;
        if (bits & shared) {
            if (sc->max_pairs >= 0 && sc->candidates >= sc->max_pairs) {
                sc->complete = 0;
                return 1;
            }
            sc->candidates++;
            sc->tested++;
            return 0;
        }
    }
    return ct_test_pair(sc, i, j, FI, have_i, FJ, have_j, ci, cj);
}

/* The pairs of the face at position i with the positions base + j of one block, j the bits of mask (their float32
 * boxes meet); returns 0 to go on, 1 to stop.  The same decisions as ct_visit pair by pair, but the pairs
 * sharing a certified corner are found for the whole block at once (ct_share_mask on the block's corner
 * indices): those of a big star dropped, those of a small star counted (candidates and tested, as ct_visit
 * counts them; both faces hold the shared vertex, so their float64 boxes meet); only the others are visited
 * one by one.  With a work bound (max_pairs >= 0) every pair goes through ct_visit, in order. */
static inline int
ct_visit_block(CtScan *sc, int64_t i, int64_t base, unsigned mask, CtFace *FI, uint8_t *have_i, CtFace *leaf,
               uint8_t *have, CtIdCache *ci, CtIdCache *cj)
{
    unsigned bits = sc->stars != NULL ? sc->stars[i] : 0;
    if (bits && sc->max_pairs < 0) {
        const int32_t *ids = ct_leaf_ids(sc, cj), *id = ct_leaf_ids(sc, ci);
        unsigned big = 0, in_small = 0;
        for (int c = 0; c < 3; c++) {
            if (!((bits >> c) & 9u)) continue;
            unsigned eq = ct_share_mask(ids, ct_id(id, i % CT_LEAF, c));
            if (bits & (8u << c)) big |= eq;
            else in_small |= eq;
        }
        mask &= ~big;
        unsigned counted = mask & in_small;
        int n = ct_popcount(counted);
        sc->candidates += n;
        sc->tested += n;
        mask &= ~counted;
        while (mask) {
            int b = ct_ctz(mask);
            mask &= mask - 1;
            if (ct_test_pair(sc, i, base + b, FI, have_i, &leaf[b], &have[b], ci, cj)) return 1;
        }
        return 0;
    }
    while (mask) {
        int b = ct_ctz(mask);
        mask &= mask - 1;
        if (ct_visit(sc, i, base + b, FI, have_i, &leaf[b], &have[b], ci, cj)) return 1;
    }
    return 0;
}

static inline int
ct_nodes_meet(const CtNode *p, const CtNode *q)
{
    return (p->lo[0] <= q->hi[0]) & (q->lo[0] <= p->hi[0]) & (p->lo[1] <= q->hi[1]) & (q->lo[1] <= p->hi[1])
           & (p->lo[2] <= q->hi[2]) & (q->lo[2] <= p->hi[2]);
}

/* Every candidate pair below the node pair (p0, q0): p0 == q0 for the pairs within one subtree; for
 * p0 != q0 the caller has checked that their boxes meet. */
static void
ct_traverse(CtScan *sc, int64_t p0, int64_t q0)
{
    size_t cap = 1024, top = 0;
    int64_t *stack = (int64_t *)malloc(2 * cap * sizeof(int64_t));
    if (stack == NULL) {
        sc->oom = 1;
        return;
    }
    const CtNode *nodes = sc->nodes;
    CtGrid gp, gq;
    memset(&gp, 0, sizeof(gp));
    memset(&gq, 0, sizeof(gq));
    int64_t gp_node = -1, gq_node = -1;
    CtIdCache cp, cq;                       /* the corner indices of the leaves p and q, read when first needed */
    cp.block = cq.block = -1;
    cp.filled = cq.filled = 0;
    stack[0] = p0;
    stack[1] = q0;
    top = 1;
    while (top > 0) {
        top--;
        sc->node_pairs++;
        int64_t pi = stack[2 * top], qi = stack[2 * top + 1];
        const CtNode *p = &nodes[pi], *q = &nodes[qi];
        if (p->apex >= 0 && p->apex == q->apex) {
            continue;                       /* every pair below is within one certified star */
        }
        if (pi == qi && sc->patch != NULL && sc->patch[pi]) {
            continue;                       /* every pair below is within one certified patch */
        }
        if (top + 4 > cap) {
            int64_t *ns = (int64_t *)realloc(stack, 4 * cap * sizeof(int64_t));
            if (ns == NULL) {
                sc->oom = 1;
                break;
            }
            stack = ns;
            cap *= 2;
        }
        if (pi == qi) {
            if (CT_IS_LEAF(p)) {
                sc->leaf_pairs++;
                int64_t pstart = CT_LEAF * CT_BLOCK_OF(p);
                int pcount = ct_leaf_count(p, sc->m);
                CtFace leaf[CT_LEAF];
                uint8_t have[CT_LEAF] = {0};
                const CtQ *blk = sc->BOX + CT_BLOCK * CT_BLOCK_OF(p);
                ct_id_cache_at(&cp, CT_BLOCK_OF(p));
                for (int a = 0; a + 1 < pcount; a++) {
                    unsigned ql[3], qh[3];          /* one grid: the steps compare as they are */
                    ct_block_query(blk, a, ql, qh);
                    unsigned mask = ct_block_mask(blk, ql, qh);
                    mask &= ~((2u << a) - 1) & ct_leaf_bits(pcount);     /* the later faces j > i only */
                    if (mask && ct_visit_block(sc, pstart + a, pstart, mask, &leaf[a], &have[a], leaf, have, &cp,
                                               &cp)) {
                        goto out;
                    }
                }
            }
            else {
                stack[2 * top] = CT_LEFT(p); stack[2 * top + 1] = CT_LEFT(p); top++;
                stack[2 * top] = CT_RIGHT(p); stack[2 * top + 1] = CT_RIGHT(p); top++;
                if (ct_nodes_meet(&nodes[CT_LEFT(p)], &nodes[CT_RIGHT(p)])) {
                    stack[2 * top] = CT_LEFT(p); stack[2 * top + 1] = CT_RIGHT(p); top++;
                }
            }
            continue;
        }
        if (CT_IS_LEAF(p) && CT_IS_LEAF(q)) {
            sc->leaf_pairs++;
            int64_t pstart = CT_LEAF * CT_BLOCK_OF(p), qstart = CT_LEAF * CT_BLOCK_OF(q);
            CtFace leaf[CT_LEAF];
            uint8_t have[CT_LEAF] = {0};
            const CtQ *pb = sc->BOX + CT_BLOCK * CT_BLOCK_OF(p);
            const CtQ *qb = sc->BOX + CT_BLOCK * CT_BLOCK_OF(q);
            if (pi != gp_node) {                 /* the leaves' grids, kept while the same leaf recurs */
                ct_grid(p, &gp);
                gp_node = pi;
            }
            if (qi != gq_node) {
                ct_grid(q, &gq);
                gq_node = qi;
            }
            ct_id_cache_at(&cp, CT_BLOCK_OF(p));
            ct_id_cache_at(&cq, CT_BLOCK_OF(q));
            /* p's faces against q's box first (on p's grid), then each that meets it against q's faces (its
             * bytes mapped back outward, then onto q's grid) */
            unsigned ql[3] = {0, 0, 0}, qh[3] = {0, 0, 0};
            int meets = 1;
            for (int c = 0; c < 3; c++) meets &= ct_grid_query(&gp, c, q->lo[c], q->hi[c], &ql[c], &qh[c]);
            unsigned pmask = meets ? ct_block_mask(pb, ql, qh) & ct_leaf_bits(ct_leaf_count(p, sc->m)) : 0u;
            unsigned qbits = ct_leaf_bits(ct_leaf_count(q, sc->m));
            /* a leaf whose faces all hold one certified big-star vertex (its apex) against a leaf that mixes
             * faces holding it with others (a fan cap's slivers and the walls beside them in one leaf): the
             * faces of the mixed leaf that hold the apex pair with every face of the other within that star,
             * pairs ct_visit_block and ct_visit leave out uncounted, so they are taken out of the masks here,
             * once per leaf pair instead of face by face (the same pairs, counts and order) */
            if (pmask && sc->stars != NULL) {
                if (q->apex >= 0) pmask &= ~ct_share_mask(ct_leaf_ids(sc, &cp), q->apex);
                if (p->apex >= 0) qbits &= ~ct_share_mask(ct_leaf_ids(sc, &cq), p->apex);
            }
            /* p's steps onto q's grid, per axis: the affine map t = A + q B of ct_grid_lo / ct_grid_hi followed
             * by T of q, widened by E (ct_pair_map); or, where a grid is not cut, one query for every face */
            CtMap map;
            if (pmask && !ct_pair_map(&gp, &gq, p, &map)) pmask = 0;     /* no face left: no map */
            while (pmask) {
                int a = ct_ctz(pmask);
                pmask &= pmask - 1;
                meets = 1;
                for (int c = 0; c < 3; c++) {
                    if (!map.affine[c]) {
                        ql[c] = map.ql[c];
                        qh[c] = map.qh[c];
                        continue;
                    }
                    double tl = (map.A[c] + (double)pb[c * CT_LEAF + a] * map.B[c]) - map.E[c];
                    double th = (map.A[c] + (double)pb[(3 + c) * CT_LEAF + a] * map.B[c]) + map.E[c];
                    if (!(tl < (double)CT_QMAX) || !(th >= 0.0)) {
                        meets = 0;
                        break;
                    }
                    ql[c] = tl > 0 ? (unsigned)tl : 0u;
                    unsigned b = th < (double)CT_QMAX ? (unsigned)th : CT_QMAX;
                    if (th < (double)CT_QMAX && (double)b < th) b++;
                    qh[c] = b;
                }
                unsigned mask = meets ? ct_block_mask(qb, ql, qh) & qbits : 0u;
                CtFace FI;
                uint8_t have_i = 0;
                if (mask && ct_visit_block(sc, pstart + a, qstart, mask, &FI, &have_i, leaf, have, &cp, &cq)) {
                    goto out;
                }
            }
            continue;
        }
        if (!CT_IS_LEAF(p) && !CT_IS_LEAF(q)) {
            /* both inner: descend both at once (the four child pairs that meet) */
            const int64_t pc[2] = {CT_LEFT(p), CT_RIGHT(p)}, qc[2] = {CT_LEFT(q), CT_RIGHT(q)};
            for (int u = 1; u >= 0; u--) {
                for (int w = 1; w >= 0; w--) {
                    if (ct_nodes_meet(&nodes[pc[u]], &nodes[qc[w]])) {
                        stack[2 * top] = pc[u]; stack[2 * top + 1] = qc[w]; top++;
                    }
                }
            }
            continue;
        }
        /* descend the inner node; push only children that meet */
        int split_p = CT_IS_LEAF(q) || (!CT_IS_LEAF(p) && (p->hi[0] - p->lo[0]) + (p->hi[1] - p->lo[1])
                                        + (p->hi[2] - p->lo[2]) >= (q->hi[0] - q->lo[0])
                                        + (q->hi[1] - q->lo[1]) + (q->hi[2] - q->lo[2]));
        if (split_p) {
            if (ct_nodes_meet(&nodes[CT_RIGHT(p)], q)) {
                stack[2 * top] = CT_RIGHT(p); stack[2 * top + 1] = qi; top++;
            }
            if (ct_nodes_meet(&nodes[CT_LEFT(p)], q)) {
                stack[2 * top] = CT_LEFT(p); stack[2 * top + 1] = qi; top++;
            }
        }
        else {
            if (ct_nodes_meet(p, &nodes[CT_RIGHT(q)])) {
                stack[2 * top] = pi; stack[2 * top + 1] = CT_RIGHT(q); top++;
            }
            if (ct_nodes_meet(p, &nodes[CT_LEFT(q)])) {
                stack[2 * top] = pi; stack[2 * top + 1] = CT_LEFT(q); top++;
            }
        }
    }
out:
    free(stack);
}

/* Threads: the node pairs near the root become tasks (each a traversal on its own), taken by ticket; each
 * thread keeps its own counters and found pairs, merged afterwards.  The set of pairs found does not depend
 * on the thread count.  With a work bound (max_pairs >= 0) the scan runs on one thread. */
#define CT_TASKS 512

typedef struct {
    CtScan *scans;              /* one per thread, sharing the read-only data of scans[0] */
    const int64_t *tasks;       /* node pairs */
    int32_t n_tasks;
    int32_t next;
} CtParallel;

static void
ct_parallel_task(void *ctx, int t, int nt)
{
    CtParallel *pp = (CtParallel *)ctx;
    CtScan *sc = &pp->scans[t];
    (void)nt;
    for (;;) {
        int32_t k = next_ticket(&pp->next);
        if (k >= pp->n_tasks || sc->oom) break;
        ct_traverse(sc, pp->tasks[2 * k], pp->tasks[2 * k + 1]);
    }
}

/* Node pairs covering every candidate pair (the distinct ones with meeting boxes), split near the root into
 * up to about CT_TASKS; their count. */
static int32_t
ct_tasks(const CtNode *nodes, const uint8_t *patch, int64_t *tasks)
{
    int32_t n = 1;
    tasks[0] = tasks[1] = CT_ROOT;
    if (patch != NULL && patch[CT_ROOT]) return 0;     /* the whole mesh one certified patch */
    for (int round = 0; round < 16 && n < CT_TASKS / 4; round++) {
        int64_t next[2 * CT_TASKS];
        int32_t m = 0;
        for (int32_t k = 0; k < n; k++) {
            int64_t pi = tasks[2 * k], qi = tasks[2 * k + 1];
            const CtNode *p = &nodes[pi], *q = &nodes[qi];
            if (pi == qi && !CT_IS_LEAF(p)) {
                int64_t add[3][2] = {{CT_LEFT(p), CT_LEFT(p)}, {CT_RIGHT(p), CT_RIGHT(p)}, {CT_LEFT(p), CT_RIGHT(p)}};
                for (int j = 0; j < 3; j++) {
                    if (j == 2 && !ct_nodes_meet(&nodes[CT_LEFT(p)], &nodes[CT_RIGHT(p)])) continue;
                    if (j < 2 && patch != NULL && patch[add[j][0]]) continue;     /* within a certified patch */
                    next[2 * m] = add[j][0];
                    next[2 * m + 1] = add[j][1];
                    m++;
                }
            }
            else if (pi != qi && !CT_IS_LEAF(p)) {
                if (ct_nodes_meet(&nodes[CT_LEFT(p)], q)) {
                    next[2 * m] = CT_LEFT(p); next[2 * m + 1] = qi; m++;
                }
                if (ct_nodes_meet(&nodes[CT_RIGHT(p)], q)) {
                    next[2 * m] = CT_RIGHT(p); next[2 * m + 1] = qi; m++;
                }
            }
            else {
                next[2 * m] = pi; next[2 * m + 1] = qi; m++;
            }
        }
        memcpy(tasks, next, (size_t)m * 2 * sizeof(int64_t));
        n = m;
    }
    return n;
}

/* Per-face preparation, split over threads by position: Morton codes and each face's projection axis and
 * zero-area flag, in the caller's order (pass 0: the rows are read in sequence); once the codes are sorted, the
 * faces in hierarchy order and their projections' orientations (pass 1), the axes and flags unpacked (pass 2);
 * and only once the sort's words, the edge twins and the stars' lists are given back, the corner indices, flags
 * and boxes in hierarchy order (pass 3), so that those 37 bytes a face never coexist with the others. */
typedef struct {
    int pass;
    int64_t m;
    const double *V;
    const void *F;
    int size;
    uint64_t *code;             /* Morton code << 31 | face index; sorted between the passes */
    double gmin[3], scale[3];
    int8_t *axis;
    uint8_t *skip;
    CtQ *box;                   /* the faces' boxes as steps on their leaf's grid, in blocks (pass 3) */
    float *lbox;                /* each leaf's float32 box (pass 3; ct_build_boxes) */
    int32_t *lapex;             /* each leaf's certified vertex common to its faces, or -1 (pass 3; ct_leaf_apex) */
    const uint8_t *cert;        /* the star certificates per vertex (ct_stars), NULL without them */
    uint8_t *stars;             /* per position, its certified corners (ct_visit; pass 3), when cert is given */
    int32_t *order;
    uint8_t *flags;
    uint8_t *fmask;             /* NULL, or per position the orientations of the face's projections (ct_patches) */
    long exact[MAX_THREADS];
    int failed[MAX_THREADS];
} CtPrep;

static void
ct_prep_task(void *ctx, int t, int nt)
{
    CtPrep *pr = (CtPrep *)ctx;
    int64_t s = (int64_t)part_start((size_t)pr->m, t, nt), e = (int64_t)part_start((size_t)pr->m, t + 1, nt);
    CtStats st = {0, 0};
    if (pr->pass == 2) {                       /* axis[f] held axis | orientations << 2: unpacked */
        for (int64_t f = s; f < e; f++) {
            pr->skip[f] = (uint8_t)((uint8_t)pr->axis[f] >> 2 == 0);
            pr->axis[f] = (int8_t)(pr->axis[f] & 3);
        }
        return;
    }
    if (pr->pass == 0) {
        for (int64_t f = s; f < e; f++) {
            const double *p0 = pr->V + 3 * index_at(pr->F, pr->size, 3 * (size_t)f);
            const double *p1 = pr->V + 3 * index_at(pr->F, pr->size, 3 * (size_t)f + 1);
            const double *p2 = pr->V + 3 * index_at(pr->F, pr->size, 3 * (size_t)f + 2);
            /* the exact orientation of the face's projection along each axis, orient2d(p1, p2, p0) (the sign
             * of orient2d(p0, p1, p2)): each filter's value is the float normal's component, n = e1 x e2 with
             * e1 = p1 - p0, e2 = p2 - p0 (the arithmetic of ct_face_normal); then the projection axis (the
             * largest |n| component, the first of equals, then the next ones until the orientation is nonzero;
             * as mesh/intersect._face_axes) and zero area when all three are zero.  axis[f] <- axis |
             * orientations << 2 (pass 2 unpacks it). */
            double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
            double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
            double n[3];
            unsigned fm = 0;
            for (int a = 0; a < 3; a++) {
                int kx = ct_plane[a][0], ky = ct_plane[a][1];
                double left = e1[kx] * e2[ky], right = e1[ky] * e2[kx];
                double det = left - right, perm = fabs(left) + fabs(right);
                int o;
                n[a] = det;
                if (perm == 0.0) {
                    o = 0;
                }
                else if (fabs(det) > CONTACT_O2 * perm) {
                    o = det > 0 ? 1 : -1;
                }
                else {
                    double a2[2] = {p1[kx], p1[ky]}, b2[2] = {p2[kx], p2[ky]}, c2[2] = {p0[kx], p0[ky]};
                    o = ct_orient2d_exact(a2, b2, c2, &st);
                }
                fm |= o > 0 ? 1u << (2 * a) : o < 0 ? 2u << (2 * a) : 0u;
            }
            int k = 0;
            for (int c = 1; c < 3; c++) {
                if (fabs(n[c]) > fabs(n[k])) k = c;
            }
            for (int tries = 0; tries < 3 && !((fm >> (2 * k)) & 3u); tries++) k = (k + 1) % 3;
            pr->axis[f] = (int8_t)(uint8_t)((unsigned)k | fm << 2);
            uint64_t code = 0;
            for (int c = 0; c < 3; c++) {
                double lo = ct_min3(p0[c], p1[c], p2[c]), hi = ct_max3(p0[c], p1[c], p2[c]);
                double q = (0.5 * (lo + hi) - pr->gmin[c]) * pr->scale[c];
                uint64_t k = q > 0 ? (uint64_t)q : 0;
                if (k > (1u << CT_MORTON_BITS) - 1) k = (1u << CT_MORTON_BITS) - 1;
                code |= ct_spread(k) << c;
            }
            pr->code[f] = code << 31 | (uint64_t)f;
        }
        pr->exact[t] += st.exact;
        pr->failed[t] |= st.failed;
        return;
    }
    if (pr->pass == 1) {                       /* the sorted codes: faces in hierarchy order (and fmask) */
        for (int64_t i = s; i < e; i++) {
            int32_t f = (int32_t)(pr->code[i] & 0x7fffffff);
            pr->order[i] = f;
            if (pr->fmask != NULL) pr->fmask[i] = (uint8_t)((uint8_t)pr->axis[f] >> 2);
        }
        return;
    }
    /* pass 3, after pass 2's unpacking: by whole blocks of hierarchy positions (a block's bytes need its
     * leaf's box, i.e. all its faces' boxes first) */
    int64_t n_blocks = (pr->m + CT_LEAF - 1) / CT_LEAF;
    int64_t b0 = (int64_t)part_start((size_t)n_blocks, t, nt), b1 = (int64_t)part_start((size_t)n_blocks, t + 1, nt);
    e = b1 * CT_LEAF < pr->m ? b1 * CT_LEAF : pr->m;
    for (int64_t blk_i = b0; blk_i < b1; blk_i++) {
        double lo[CT_LEAF][3], hi[CT_LEAF][3];
        int32_t ids[CT_IDBLOCK];                 /* the block's corner indices (ct_id), for its apex and bits */
        CtNode leaf;
        int64_t start = blk_i * CT_LEAF, count = pr->m - start < CT_LEAF ? pr->m - start : CT_LEAF;
        CtQ *blk = pr->box + CT_BLOCK * blk_i;
        for (int c = 0; c < 3; c++) {
            leaf.lo[c] = INFINITY;
            leaf.hi[c] = -INFINITY;
        }
        for (int64_t j = 0; j < count; j++) {
            int64_t i = start + j;
            /* the faces are read in hierarchy order, i.e. at random in the caller's: their rows are fetched
             * CT_AHEAD positions ahead, their corners CT_AHEAD / 2 ahead (from the rows fetched by then) */
            if (i + CT_AHEAD < e) {
                ct_prefetch((const char *)pr->F + (size_t)pr->size * 3 * (size_t)pr->order[i + CT_AHEAD]);
            }
            if (i + CT_AHEAD / 2 < e) {
                size_t g = 3 * (size_t)pr->order[i + CT_AHEAD / 2];
                for (int k = 0; k < 3; k++) ct_prefetch(pr->V + 3 * index_at(pr->F, pr->size, g + (size_t)k));
            }
            int64_t f = pr->order[i];
            const double *p0 = pr->V + 3 * index_at(pr->F, pr->size, 3 * (size_t)f);
            const double *p1 = pr->V + 3 * index_at(pr->F, pr->size, 3 * (size_t)f + 1);
            const double *p2 = pr->V + 3 * index_at(pr->F, pr->size, 3 * (size_t)f + 2);
            pr->flags[i] = (uint8_t)((unsigned)pr->axis[f] | (unsigned)pr->skip[f] << 2);
            unsigned bits = 0;
            for (int k = 0; k < 3; k++) {
                int32_t x = (int32_t)index_at(pr->F, pr->size, 3 * (size_t)f + (size_t)k);
                ids[k * CT_LEAF + j] = x;
                if (pr->cert != NULL) {
                    uint8_t q = pr->cert[x];
                    bits |= q == CT_STAR_BIG ? 8u << k : q == CT_STAR_SMALL_CERT ? 1u << k : 0u;
                }
            }
            if (pr->stars != NULL) pr->stars[i] = (uint8_t)bits;
            for (int c = 0; c < 3; c++) {
                lo[j][c] = ct_min3(p0[c], p1[c], p2[c]);
                hi[j][c] = ct_max3(p0[c], p1[c], p2[c]);
                float l32 = ct_f32_down(lo[j][c]), h32 = ct_f32_up(hi[j][c]);
                if (l32 < leaf.lo[c]) leaf.lo[c] = l32;
                if (h32 > leaf.hi[c]) leaf.hi[c] = h32;
            }
        }
        for (int c = 0; c < 3; c++) {
            pr->lbox[6 * blk_i + c] = leaf.lo[c];
            pr->lbox[6 * blk_i + 3 + c] = leaf.hi[c];
        }
        CtGrid grid;
        ct_grid(&leaf, &grid);
        for (int64_t j = 0; j < CT_LEAF; j++) {
            for (int c = 0; c < 3; c++) {
                if (j < count) {
                    ct_grid_store(&grid, c, lo[j][c], hi[j][c], &blk[c * CT_LEAF + j], &blk[(3 + c) * CT_LEAF + j]);
                }
                else {                                  /* past the last face: no box, no vertex */
                    blk[c * CT_LEAF + j] = (CtQ)CT_QMAX;
                    blk[(3 + c) * CT_LEAF + j] = 0;
                }
            }
        }
        pr->lapex[blk_i] = (int32_t)ct_leaf_apex(ids, pr->cert, 0, count);
    }
}

/* contact_scan(vertices, faces, max_pairs[, threads[, star_faces]]) -> (a, b, kind, candidates, tested, exact, complete,
 * axis, degenerate): found pairs as int64 / int8 bytes, per-face projection axis (int8 bytes) and zero-area
 * flags (uint8 bytes) in the caller's face order. */
static PyObject *
accel_contact_scan(PyObject *self, PyObject *args)
{
    PyObject *objs[2];
    long long max_pairs;
    int threads = 1;
    long long star_faces = 0;
    int patches = 0;
    if (!PyArg_ParseTuple(args, "OOL|iLp", &objs[0], &objs[1], &max_pairs, &threads, &star_faces, &patches)) {
        return NULL;
    }
    Py_buffer views[2];
    int got = 0;
    PyObject *result = NULL;
    CtNode *nodes = NULL;
    uint64_t *code = NULL;
    CtQ *box = NULL;
    float *lbox = NULL;
    int32_t *order = NULL;
    int32_t *lapex = NULL;
    size_t nodes_bytes = 0, code_bytes = 0, box_bytes = 0, lbox_bytes = 0, order_bytes = 0, ids_bytes = 0;
    uint8_t *flags = NULL;
    int8_t *axis_out = NULL;
    uint8_t *skip_out = NULL;
    uint8_t *cert = NULL;
    uint8_t *stars = NULL;
    uint8_t *patch = NULL;
    uint8_t *fmask = NULL;
    int32_t *twin = NULL;
    CtScan sc;
    memset(&sc, 0, sizeof(sc));
    CtArena ar;
    memset(&ar, 0, sizeof(ar));
    ar.poison = getenv("INERTIA_TOOL_CT_POISON") != NULL;
    for (; got < 2; got++) {
        if (PyObject_GetBuffer(objs[got], &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
            goto done;
        }
    }
    {
        Py_buffer *vv = &views[0], *fv = &views[1];
        int fsize = signed_int_size(fv);
        if (native_code(vv->format) != 'd' || vv->itemsize != 8 || vv->ndim != 2 || vv->shape[1] != 3
            || fsize == 0 || fv->ndim != 2 || fv->shape[1] != 3) {
            PyErr_SetString(PyExc_ValueError, "Expected vertices (n, 3) float64 and faces (m, 3) int32 or int64, "
                            "both C-contiguous");
            goto done;
        }
        int64_t n = vv->shape[0], m = fv->shape[0];
        const void *F = fv->buf;
        const double *V = (const double *)vv->buf;
        Py_ssize_t bad;
        Py_BEGIN_ALLOW_THREADS
        bad = first_bad_index(F, fsize, 3 * (size_t)m, n);
        Py_END_ALLOW_THREADS
        if (bad >= 0) {
            PyErr_Format(PyExc_ValueError, "Expected face indices in [0, %lld), found %lld",
                         (long long)n, (long long)index_at(F, fsize, (size_t)bad));
            goto done;
        }
        if (n > (int64_t)INT32_MAX || m > (int64_t)INT32_MAX - 1) {
            PyErr_Format(PyExc_ValueError, "Expected fewer than 2**31 vertices and faces, got %lld and %lld",
                         (long long)n, (long long)m);
            goto done;
        }
        sc.complete = 1;
        sc.max_pairs = max_pairs;
        if ((size_t)m > SIZE_MAX / (2 * sizeof(CtFace))) {
            PyErr_NoMemory();
            goto done;
        }
        size_t mm = m > 0 ? (size_t)m : 1;
        size_t n_blocks = (mm + CT_LEAF - 1) / CT_LEAF;
        nodes_bytes = (2 * n_blocks + 1) * sizeof(CtNode);     /* a leaf per block: 2 n_blocks - 1 nodes, from 1 */
        /* the sort's keys and scratch (2 m words), then the stars' lists, in one mapping; the boxes and corner
         * indices are mapped only once it is given back (below) */
        code_bytes = 2 * mm * sizeof(uint64_t);
        if (ct_stars_scratch(n, m) > code_bytes) code_bytes = ct_stars_scratch(n, m);
        box_bytes = n_blocks * CT_BLOCK * sizeof(CtQ);         /* two bytes per bound */
        lbox_bytes = n_blocks * 6 * sizeof(float);
        order_bytes = n_blocks * CT_LEAF * sizeof(int32_t);   /* whole leaves: the size of pos (below) */
        /* the size of corner indices in blocks (12 bytes a face), no longer kept for the traversal (CtIdCache),
         * is still the one the twins are asked for in, so that the boxes (the same 12) take their block */
        ids_bytes = n_blocks * CT_IDBLOCK * sizeof(int32_t);
        nodes = (CtNode *)ct_alloc(&ar, &nodes_bytes);
        code = (uint64_t *)ct_alloc(&ar, &code_bytes);
        order = (int32_t *)ct_alloc(&ar, &order_bytes);
        axis_out = (int8_t *)malloc(mm);
        skip_out = (uint8_t *)malloc(mm);
        if (nodes == NULL || code == NULL || order == NULL || axis_out == NULL || skip_out == NULL) {
            PyErr_NoMemory();
            goto done;
        }
        int oom = 0, failed = 0;
        /* the stage clocks only when profiling: CLOCK_PROCESS_CPUTIME_ID is a system call, and reading it at
         * every stage was about half of a 12-face scan's time (15.7 -> 8.6 us a call) */
        const char *profile_env = getenv("INERTIA_TOOL_CT_PROFILE");
        int profile = profile_env != NULL, wall = profile && strcmp(profile_env, "wall") == 0;
        double clk[12] = {0}, rss[12] = {0}, hwm[12] = {0};
        Py_BEGIN_ALLOW_THREADS
        clk[0] = profile ? ct_clock(wall) : 0.0;
        int nt = thread_count(threads, (size_t)m, 20000);
        CtPrep pr;
        memset(&pr, 0, sizeof(pr));
        pr.m = m;
        pr.V = V;
        pr.F = F;
        pr.size = fsize;
        pr.code = code;
        pr.axis = axis_out;
        pr.skip = skip_out;
        pr.order = order;
        if (patches && max_pairs < 0) {
            fmask = (uint8_t *)malloc(mm);         /* NULL (out of memory): no patches, the same pairs */
            pr.fmask = fmask;
        }
        /* the Morton grid: box centres of the faces, 2^16 cells per axis over their range */
        double gmin[3] = {INFINITY, INFINITY, INFINITY}, gmax[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int64_t i = 0; i < n; i++) {       /* every vertex: a bound of the box centres */
            const double *p = V + 3 * i;
            for (int c = 0; c < 3; c++) {
                if (p[c] < gmin[c]) gmin[c] = p[c];
                if (p[c] > gmax[c]) gmax[c] = p[c];
            }
        }
        for (int c = 0; c < 3; c++) {
            double span = gmax[c] - gmin[c];
            pr.gmin[c] = gmin[c];
            pr.scale[c] = span > 0 ? (double)((1u << CT_MORTON_BITS) - 1) / span : 0.0;
        }
        pr.pass = 0;
        run_parallel(nt, ct_prep_task, &pr);
        clk[1] = profile ? ct_clock(wall) : 0.0;
        if (profile) ct_resident_mb(&rss[1], &hwm[1]);
        if (ct_radix_sort(code, code + mm, m) < 0) {
            oom = 1;
        }
        else {
            clk[2] = profile ? ct_clock(wall) : 0.0;
            if (profile) ct_resident_mb(&rss[2], &hwm[2]);
            pr.pass = 1;
            run_parallel(nt, ct_prep_task, &pr);
            pr.pass = 2;
            run_parallel(nt, ct_prep_task, &pr);
            clk[3] = profile ? ct_clock(wall) : 0.0;
            if (profile) ct_resident_mb(&rss[3], &hwm[3]);
            for (int t = 0; t < MAX_THREADS; t++) {
                sc.exact += pr.exact[t];
                failed |= pr.failed[t];
            }
            /* order holds the face indices in hierarchy order: code's memory is the stars' scratch now, its
             * pages given back until then (issue 25: resident under the positions and the twins, the sort words
             * were the check's high point) */
            ct_drop_pages(code, code_bytes);
        }
        int64_t n_nodes = 0;
        int64_t star_min = star_faces < CT_STAR_MIN ? star_faces : CT_STAR_MIN;
        if (!oom && !failed && m >= 2 && star_faces > 0) {
            cert = (uint8_t *)malloc((size_t)n);
            if (cert == NULL) oom = 1;
        }
        int32_t *pos = NULL;
        /* asked for in the sizes of the corner indices and the order (whole leaves; the tails are not written)
         * so that those reuse these blocks (CtArena) */
        size_t twin_bytes = ids_bytes, pos_bytes = order_bytes;
        if (!oom && !failed && m >= 2 && cert != NULL && fmask != NULL) {
            /* mappings, not the heap: a heap block freed below the top stays resident (and glibc's mmap
             * threshold rises to the size of a block once freed), so the twins would sit under the boxes */
            twin = (int32_t *)ct_alloc(&ar, &twin_bytes);    /* NULL: no patches, the same pairs */
            pos = (int32_t *)ct_alloc(&ar, &pos_bytes);
            if (twin == NULL || pos == NULL) {
                ct_free(&ar, twin, twin_bytes);
                ct_free(&ar, pos, pos_bytes);
                twin = NULL;
                pos = NULL;
            }
        }
        if (!oom && !failed && m >= 2 && twin != NULL) {
            /* with patches: the faces across each edge by hierarchy position (ct_twins into twin, from every
             * vertex's faces listed in code's memory, then given back), the patches on the hierarchy's shape,
             * the twins given back, then the star certificates of the vertices whose faces are not all in one
             * certified patch (the others decide no pair), from their lists alone */
            int64_t *off, total;
            int32_t *vfaces;
            for (int64_t i = 0; i < m; i++) pos[order[i]] = (int32_t)i;
            clk[8] = profile ? ct_clock(wall) : 0.0;
            if (profile) ct_resident_mb(&rss[8], &hwm[8]);
            if (ct_twins(F, fsize, n, m, code, code_bytes, pos, twin, nt, ct_twin_rounds(m)) < 0) {
                oom = 1;
            }
            ct_drop_pages(pos, pos_bytes);      /* dead until it holds the patch labels (below) */
            if (profile) ct_resident_mb(&rss[0], &hwm[0]);     /* the twins (clk[0] is the start) */
            /* unmapped, not kept for a later phase: held under the stars' lists, the sort words' 16 bytes a face
             * raised the check's high point by 6 (the twins' block, kept for the boxes, is enough to hold) */
            ct_drop(code, code_bytes);
            code = NULL;
            code_bytes = 0;
            clk[9] = profile ? ct_clock(wall) : 0.0;
            if (profile) ct_resident_mb(&rss[9], &hwm[9]);
            if (!oom) {
                int32_t *across = twin;
                for (int64_t i = 0; i < 3 * m; i++) {
                    if (across[i] == -2) {
                        fmask[i / 3] = 0;          /* not one face across: in no patch */
                        across[i] = -1;
                    }
                }
                n_nodes = ct_build_tree(nodes, m);
                clk[10] = profile ? ct_clock(wall) : 0.0;
                if (profile) ct_resident_mb(&rss[10], &hwm[10]);
                patch = (uint8_t *)malloc((size_t)n_nodes);
                if (patch == NULL || ct_patches(nodes, n_nodes, F, fsize, order, fmask, across, V, m, patch) < 0) {
                    free(patch);
                    patch = NULL;           /* out of memory: the scan without patches, the same pairs */
                }
                clk[7] = profile ? ct_clock(wall) : 0.0;
                if (profile) ct_resident_mb(&rss[7], &hwm[7]);
                int32_t *label = pos;                  /* pos is done with: each face's certified patch */
                if (patch != NULL) ct_patch_labels(nodes, patch, order, m, label);
                /* the stars' lists in the twins' block, dead now and kept resident for the boxes (issue 25: a
                 * block of their own, its offsets written whole, raised the check's high point, and the boxes then
                 * faulted in fresh pages), each part in a block of its own only where it does not fit */
                size_t off_bytes = (size_t)(n > 0 ? n : 1) * sizeof(int64_t), faces_bytes = 0;
                size_t own_off_bytes = off_bytes, own_faces_bytes = 0;
                void *own_off = NULL, *own_faces = NULL;
                off = off_bytes <= twin_bytes ? (int64_t *)(void *)twin
                                              : (int64_t *)(own_off = ct_alloc(&ar, &own_off_bytes));
                if (off == NULL) {
                    oom = 1;
                }
                else {
                    total = ct_star_count(n, F, fsize, m, star_min, patch != NULL ? label : NULL, off);
                    faces_bytes = (size_t)(total > 0 ? total : 1) * sizeof(int32_t);
                    own_faces_bytes = faces_bytes;
                    vfaces = own_off == NULL && off_bytes + faces_bytes <= twin_bytes
                             ? (int32_t *)(void *)((char *)twin + off_bytes)
                             : (int32_t *)(own_faces = ct_alloc(&ar, &own_faces_bytes));
                    if (vfaces == NULL) {
                        oom = 1;
                    }
                    else {
                        ct_star_fill(F, fsize, m, off, vfaces);
                        if (ct_star_certs(V, n, F, fsize, off, vfaces, total, star_min, star_faces, cert, nt,
                                          patch != NULL ? label : NULL) < 0) {
                            oom = 1;
                        }
                    }
                }
                ct_free(&ar, own_faces, own_faces_bytes);
                ct_free(&ar, own_off, own_off_bytes);
                ct_free(&ar, twin, twin_bytes);        /* for the boxes (the same 12 bytes a face) */
                twin = NULL;
                clk[11] = profile ? ct_clock(wall) : 0.0;
                if (profile) ct_resident_mb(&rss[11], &hwm[11]);
            }
        }
        else if (!oom && !failed && m >= 2) {
            if (cert != NULL && ct_stars(V, n, F, fsize, m, star_min, star_faces, cert, nt, code) < 0) {
                oom = 1;
            }
            n_nodes = ct_build_tree(nodes, m);
        }
        ct_free(&ar, pos, pos_bytes);
        ct_free(&ar, twin, twin_bytes);
        twin = NULL;
        /* the sort's words and the stars' lists, the twins and the positions are given back before the boxes
         * and corner indices are written: the check's high point is then the traversal's arrays alone */
        ct_free(&ar, code, code_bytes);
        code = NULL;
        code_bytes = 0;
        if (!oom && !failed && m >= 2) {
            box = (CtQ *)ct_alloc(&ar, &box_bytes);
            lbox = (float *)ct_alloc(&ar, &lbox_bytes);
            lapex = (int32_t *)malloc(n_blocks * sizeof(int32_t));
            flags = (uint8_t *)malloc(mm);
            stars = cert != NULL ? (uint8_t *)malloc(mm) : NULL;
            if (box == NULL || lbox == NULL || lapex == NULL || flags == NULL || (cert != NULL && stars == NULL)) {
                oom = 1;
            }
            ct_arena_trim(&ar);                /* the blocks no array of the traversal took: unmapped before the
                                                  boxes are written (the positions' would sit under them) */
        }
        if (!oom && !failed && m >= 2) {
            pr.box = box;
            pr.lbox = lbox;
            pr.lapex = lapex;
            pr.cert = cert;
            pr.stars = stars;
            pr.flags = flags;
            pr.pass = 3;
            run_parallel(thread_count(threads, (size_t)n_blocks, 20000 / CT_LEAF), ct_prep_task, &pr);
            ct_build_boxes(nodes, n_nodes, lbox, lapex);
            ct_free(&ar, lbox, lbox_bytes);         /* the leaves' boxes are in the nodes now */
            lbox = NULL;
            free(lapex);
            lapex = NULL;
        }
        ct_arena_trim(&ar);                    /* every array of the traversal is taken: the rest unmapped */
        clk[4] = profile ? ct_clock(wall) : 0.0;
        if (profile) ct_resident_mb(&rss[4], &hwm[4]);
        if (!oom && !failed && m >= 2) {
            /* each position's certified corners (stars) were set by pass 3 */
            clk[5] = profile ? ct_clock(wall) : 0.0;
            if (profile) ct_resident_mb(&rss[5], &hwm[5]);
            sc.stars = cert != NULL ? stars : NULL;
            sc.patch = patch;
            sc.BOX = box;
            sc.order = order;
            sc.F = F;
            sc.fsize = fsize;
            sc.flags = flags;
            sc.V = V;
            sc.nodes = nodes;
            sc.m = m;
            if (max_pairs >= 0) nt = 1;
            if (nt == 1) {
                ct_traverse(&sc, CT_ROOT, CT_ROOT);
            }
            else {
                CtScan scans[MAX_THREADS];
                int64_t tasks[2 * CT_TASKS];
                CtParallel pp;
                for (int t = 0; t < nt; t++) {
                    scans[t] = sc;
                    scans[t].exact = 0;
                }
                pp.scans = scans;
                pp.tasks = tasks;
                pp.n_tasks = ct_tasks(nodes, sc.patch, tasks);
                pp.next = 0;
                run_parallel(nt, ct_parallel_task, &pp);
                long exact0 = sc.exact;
                for (int t = 0; t < nt; t++) {          /* merge into sc */
                    CtScan *u = &scans[t];
                    if (t > 0) {
                        sc.candidates += u->candidates;
                        sc.node_pairs += u->node_pairs;
                        sc.leaf_pairs += u->leaf_pairs;
                        sc.loads += u->loads;
                        sc.tested += u->tested;
                        sc.exact += u->exact;
                        sc.oom |= u->oom;
                        for (size_t i = 0; i < u->found.n && !sc.oom; i++) {
                            if (ct_found_push(&sc.found, u->found.a[i], u->found.b[i], u->found.kind[i]) < 0) {
                                sc.oom = 1;
                            }
                        }
                        free(u->found.a);
                        free(u->found.b);
                        free(u->found.kind);
                    }
                    else {
                        sc = scans[0];
                        sc.exact += exact0;
                    }
                }
            }
        }
        oom |= sc.oom;
        clk[6] = profile ? ct_clock(wall) : 0.0;
        if (profile) ct_resident_mb(&rss[6], &hwm[6]);
        Py_END_ALLOW_THREADS
        if (profile) {
            if (clk[11] > 0) {
                fprintf(stderr, "contact_scan %lld faces: codes %.6f sort %.6f order %.6f lists %.6f twins %.6f "
                        "patches %.6f stars %.6f boxes+apex+bits %.6f traverse %.6f s; ",
                        (long long)m, clk[1] - clk[0], clk[2] - clk[1], clk[3] - clk[2], clk[8] - clk[3],
                        clk[10] - clk[8], clk[7] - clk[10], clk[11] - clk[7], clk[5] - clk[11], clk[6] - clk[5]);
            }
            else {
                fprintf(stderr, "contact_scan %lld faces: codes %.6f sort %.6f order %.6f stars+boxes %.6f "
                        "traverse %.6f s; ", (long long)m, clk[1] - clk[0], clk[2] - clk[1], clk[3] - clk[2],
                        clk[5] - clk[3], clk[6] - clk[5]);
            }
            fprintf(stderr, "candidates %lld tested %lld; node pairs %lld leaf pairs %lld pair tests %lld; "
                    "MB mapped %.1f reused %.1f\n", sc.candidates, sc.tested, sc.node_pairs, sc.leaf_pairs,
                    sc.loads, ar.mapped / 1e6, ar.reused / 1e6);
            static const int at[11] = {1, 2, 3, 8, 0, 9, 10, 7, 11, 4, 6};
            static const char *const what[11] = {"codes", "sort", "order", "positions", "twins", "sort words",
                                                 "tree", "patches", "stars", "boxes", "traverse"};
            fprintf(stderr, "contact_scan resident MB after each stage, now / at most so far (VmRSS / VmHWM):");
            for (int k = 0; k < 11; k++) fprintf(stderr, " %s %.0f / %.0f", what[k], rss[at[k]], hwm[at[k]]);
            fprintf(stderr, "\n");
        }
        if (oom) {
            PyErr_NoMemory();
            goto done;
        }
        if (failed) {
            PyErr_SetString(PyExc_OverflowError, "contact_scan: an exact orientation of a face outgrew its "
                            "expansion");
            goto done;
        }
        PyObject *pa = PyBytes_FromStringAndSize((const char *)sc.found.a, (Py_ssize_t)(sc.found.n * 8));
        PyObject *pb = PyBytes_FromStringAndSize((const char *)sc.found.b, (Py_ssize_t)(sc.found.n * 8));
        PyObject *pk = PyBytes_FromStringAndSize((const char *)sc.found.kind, (Py_ssize_t)sc.found.n);
        PyObject *px = PyBytes_FromStringAndSize((const char *)axis_out, (Py_ssize_t)m);
        PyObject *ps = PyBytes_FromStringAndSize((const char *)skip_out, (Py_ssize_t)m);
        if (pa && pb && pk && px && ps) {
            result = Py_BuildValue("(OOOLLlOOO)", pa, pb, pk, sc.candidates, sc.tested, sc.exact,
                                   sc.complete ? Py_True : Py_False, px, ps);
        }
        Py_XDECREF(pa);
        Py_XDECREF(pb);
        Py_XDECREF(pk);
        Py_XDECREF(px);
        Py_XDECREF(ps);
    }
done:
    for (int i = 0; i < got; i++) {
        PyBuffer_Release(&views[i]);
    }
    ct_free(&ar, nodes, nodes_bytes);
    ct_free(&ar, code, code_bytes);
    ct_free(&ar, box, box_bytes);
    ct_free(&ar, lbox, lbox_bytes);
    ct_free(&ar, order, order_bytes);
    free(lapex);
    free(flags);
    free(axis_out);
    free(skip_out);
    free(cert);
    free(stars);
    free(patch);
    free(fmask);
    free(sc.found.a);
    free(sc.found.b);
    free(sc.found.kind);
    ct_arena_release(&ar);
    return result;
}

/* ======================================================================================================
 * 9. edge_point_candidates -- boundary vertices near the interior of a boundary edge (mesh/seal.py)
 *
 * The candidates of seal.on_edge_vertices and seal._split_t_junctions, which then apply their own tests: every
 * (edge, point) pair, the point not an end of the edge a-b nor a copy of one (equal coordinates: both callers
 * reject a point at distance 0 from the nearer end; a COLLADA soup's copies were ~9 pairs per edge), with
 *     0 < t = ((m-a).(b-a)) / |b-a|^2 < 1 (widened by 1e-12) and
 *     |m - (a + t (b-a))| <= max(gap, 2 rtol min(|m-a|, |m-b|)) + 64 eps (|b-a| + scale),
 * tested on squares without roots (a superset of the pairs that pass the callers' tests: those are
 * dist <= gap or dist <= rtol * to_end, evaluated by numpy in another order, so equal to a few ulps).  Each pair
 * once, by edge.  The points are bucketed into cubic cells of side `cell` (the cell of a point is
 * floor((x - lo) / cell) per axis, monotone in x), sorted by the Morton code of their cell (a radix sort), so
 * that the points of a cell, and of nearby cells, lie together; a hash table of the occupied cells' codes
 * (blocks of 8^3 cells hashed, the cells of a block kept together) finds them.  The edges are visited in the
 * Morton order of their first end's cell, so consecutive edges read nearby cells.  Each edge is cut into pieces
 * no longer than cell / 2 and every cell met by a piece's box, widened by the distance above, is visited (those
 * of the previous piece's box once): a pair that passes lies in one of those boxes, and the test alone decides.
 * A cell's slot in the table holds its span of sorted points, and each sorted point its coordinates and vertex
 * together (one read each).  The edges are searched on `threads` threads, in blocks of the sorted order handed
 * to whichever thread is free; each edge's pairs come from one thread, so the merged list does not depend on
 * the count.
 * The seconds of a soup's T-vertex search (every vertex on the boundary) were a k-d tree's Python lists (~9
 * points per edge), then 5.5 s of this search in the edges' file order on a 1.3M-face soup (random access).
 * ====================================================================================================== */

#include <float.h>

#define OE_BITS 21
#define OE_MAXCELL ((int64_t)1 << OE_BITS)
#define OE_EMPTY UINT64_MAX
#define OE_RADIX_BITS 11
#define OE_RADIX (1 << OE_RADIX_BITS)
#define OE_PASSES 6                                  /* 6 x 11 bits cover the 63 bits of a code */
#define OE_BLOCK_BITS 15                             /* close_groups' blocks: 32^3 cells */

/* The 21 low bits of v spread to every third bit (bit b to bit 3b). */
static inline uint64_t
oe_spread(uint64_t v)
{
    v &= 0x1fffffULL;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}

/* Every third bit of v (from bit 0) gathered into the 21 low bits: the inverse of oe_spread. */
static inline int64_t
oe_compact(uint64_t v)
{
    v &= 0x1249249249249249ULL;
    v = (v | v >> 2) & 0x10c30c30c30c30c3ULL;
    v = (v | v >> 4) & 0x100f00f00f00f00fULL;
    v = (v | v >> 8) & 0x1f0000ff0000ffULL;
    v = (v | v >> 16) & 0x1f00000000ffffULL;
    v = (v | v >> 32) & 0x1fffffULL;
    return (int64_t)v;
}

static inline void
oe_prefetch(const void *p)
{
#if defined(__GNUC__) || defined(__clang__)
    __builtin_prefetch(p);
#else
    (void)p;
#endif
}

static inline uint64_t
oe_mix(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ULL;
    x ^= x >> 33;
    return x;
}

/* The Morton code of a cell (x in the lowest of each three bits): a cell's 9 lowest bits are its place in
 * its block of 8 x 8 x 8 cells, and every aligned block of 2^j cells per axis is one range of codes. */
static inline uint64_t
oe_code(int64_t ix, int64_t iy, int64_t iz)
{
    return oe_spread((uint64_t)ix) | (oe_spread((uint64_t)iy) << 1) | (oe_spread((uint64_t)iz) << 2);
}

/* The slot of a code: its block of 8^3 cells is hashed, the cells of a block keep their order inside it, so
 * neighbouring cells lie close in the table. */
static inline size_t
oe_hash(uint64_t code, size_t mask)
{
    return (size_t)((oe_mix(code >> 9) << 9) | (code & 511)) & mask;
}

typedef struct {
    uint64_t key;                 /* the cell's code, OE_EMPTY for a free slot */
    uint64_t run;                 /* close_groups' blocks: the first run's rank; the grid's cells: their span */
} OeSlot;

/* The span of the occupied cell `code` in the grid's table (its first sorted point in the low 32 bits, the end
 * in the high 32: read with the slot, not from another array), or OE_EMPTY. */
static inline uint64_t
oe_find(const OeSlot *table, size_t mask, uint64_t code)
{
    size_t s = oe_hash(code, mask);
    while (table[s].key != OE_EMPTY) {
        if (table[s].key == code) {
            return table[s].run;
        }
        s = (s + 1) & mask;
    }
    return OE_EMPTY;
}

/* floor((x - lo) / cell) as an integer: truncation corrected below zero (floor() is a library call without
 * SSE4.1, several per edge piece); the library's floor beyond 2^62 (never a grid index: refused by the callers) */
static inline int64_t
oe_cell(double x, double lo, double cell)
{
    const double q = (x - lo) / cell;
    if (!(fabs(q) < 4.611686018427387904e18)) {
        return (int64_t)floor(q);
    }
    const int64_t i = (int64_t)q;
    return i - (q < (double)i);
}

static inline double
oe_norm(double x, double y, double z)
{
    return sqrt((x * x + y * y) + z * z);
}

/* Sort code[0..n) ascending, carrying idx along (stable: least significant digit first, 11 bits a pass,
 * passes whose digit is the same in every code skipped).  The sorted arrays end in *code / *idx, which may
 * be swapped with the scratch arrays; returns -1 when out of memory. */
static int
oe_radix_sort(uint64_t **code, uint32_t **idx, uint64_t **code2, uint32_t **idx2, size_t n)
{
    size_t *hist = (size_t *)calloc((size_t)OE_PASSES * OE_RADIX, sizeof(size_t));
    if (hist == NULL) {
        return -1;
    }
    const uint64_t *c0 = *code;
    for (size_t i = 0; i < n; i++) {
        uint64_t c = c0[i];
        for (int d = 0; d < OE_PASSES; d++) {
            hist[(size_t)d * OE_RADIX + ((c >> (d * OE_RADIX_BITS)) & (OE_RADIX - 1))]++;
        }
    }
    for (int d = 0; d < OE_PASSES; d++) {
        size_t *h = hist + (size_t)d * OE_RADIX, at = 0;
        int single = 0;
        for (int b = 0; b < OE_RADIX; b++) {
            single |= h[b] == n;
            size_t count = h[b];
            h[b] = at;
            at += count;
        }
        if (single) {
            continue;
        }
        const uint64_t *src = *code;
        const uint32_t *isrc = *idx;
        uint64_t *dst = *code2;
        uint32_t *idst = *idx2;
        for (size_t i = 0; i < n; i++) {
            size_t to = h[(src[i] >> (d * OE_RADIX_BITS)) & (OE_RADIX - 1)]++;
            dst[to] = src[i];
            idst[to] = isrc[i];
        }
        uint64_t *tc = *code;
        *code = *code2;
        *code2 = tc;
        uint32_t *ti = *idx;
        *idx = *idx2;
        *idx2 = ti;
    }
    free(hist);
    return 0;
}

/* Points bucketed into cubic cells: sorted by the Morton code of their cell, each occupied cell a run of
 * them, found through a hash table of codes. */
/* A sorted point of the grid with a table: its coordinates and vertex together, one read for both. */
typedef struct {
    double x[3];
    int64_t vertex;               /* pts[idx], or idx without pts */
} OePoint;

typedef struct {
    double lo[3], cell;
    size_t p, runs, mask;
    int64_t top[3];               /* the largest cell index used, per axis */
    OeSlot *table;                /* with a table: each occupied cell's code and span */
    uint64_t *code;               /* (p) the sorted codes (while building) */
    uint32_t *idx;                /* (p) the position in the input of each sorted point */
    uint32_t *start;              /* (runs + 1) the first sorted point of each run */
    uint64_t *run_code;           /* (runs) */
    double *coords;               /* (3 p) the points in sorted order (without a table) */
    OePoint *point;               /* (p) the points in sorted order with their vertices (with a table) */
} OeGrid;

static void
oe_grid_free(OeGrid *g)
{
    free(g->table);
    free(g->code);
    free(g->idx);
    free(g->start);
    free(g->run_code);
    free(g->coords);
    free(g->point);
}

/* Bucket the points xyz(i), i < p (at `stride` doubles apart from `base`, gathered through `pts` when not
 * NULL) into cells of side `cell` above `lo`.  Returns 0, -1 out of memory, -2 a cell index beyond 21 bits. */
static int
oe_grid_build(OeGrid *g, const double *base, const int64_t *pts, size_t p, const double lo[3], double cell,
              int with_table)
{
    memset(g, 0, sizeof(*g));
    g->p = p;
    g->cell = cell;
    memcpy(g->lo, lo, sizeof(g->lo));
    uint64_t *code2 = NULL;
    uint32_t *idx2 = NULL;
    g->code = (uint64_t *)malloc((p ? p : 1) * sizeof(uint64_t));
    g->idx = (uint32_t *)malloc((p ? p : 1) * sizeof(uint32_t));
    code2 = (uint64_t *)malloc((p ? p : 1) * sizeof(uint64_t));
    idx2 = (uint32_t *)malloc((p ? p : 1) * sizeof(uint32_t));
    if (g->code == NULL || g->idx == NULL || code2 == NULL || idx2 == NULL) {
        free(code2);
        free(idx2);
        return -1;
    }
    int64_t top[3] = {0, 0, 0};
    for (size_t i = 0; i < p; i++) {
        const double *q = base + 3 * (pts ? pts[i] : (int64_t)i);
        int64_t c[3];
        for (int a = 0; a < 3; a++) {
            c[a] = oe_cell(q[a], lo[a], cell);
            if (c[a] < 0 || c[a] >= OE_MAXCELL) {
                free(code2);
                free(idx2);
                return -2;
            }
            top[a] = c[a] > top[a] ? c[a] : top[a];
        }
        g->code[i] = oe_code(c[0], c[1], c[2]);
        g->idx[i] = (uint32_t)i;
    }
    memcpy(g->top, top, sizeof(top));
    int sorted = oe_radix_sort(&g->code, &g->idx, &code2, &idx2, p);
    free(code2);
    free(idx2);
    if (sorted < 0) {
        return -1;
    }
    size_t runs = 0;
    for (size_t i = 0; i < p; i++) {
        runs += i == 0 || g->code[i] != g->code[i - 1];
    }
    size_t size = 1024;
    while (with_table && size < 2 * runs) {
        size *= 2;
    }
    g->runs = runs;
    g->mask = size - 1;
    g->table = (OeSlot *)malloc(size * sizeof(OeSlot));
    g->start = (uint32_t *)malloc((runs + 1) * sizeof(uint32_t));
    g->run_code = (uint64_t *)malloc((runs ? runs : 1) * sizeof(uint64_t));
    if (with_table) {
        g->point = (OePoint *)malloc((p ? p : 1) * sizeof(OePoint));
    }
    else {
        g->coords = (double *)malloc((p ? 3 * p : 1) * sizeof(double));
    }
    if (g->table == NULL || g->start == NULL || g->run_code == NULL || (with_table ? g->point == NULL :
                                                                        g->coords == NULL)) {
        return -1;
    }
    for (size_t s = 0; s < size; s++) {
        g->table[s].key = OE_EMPTY;
    }
    size_t r = 0;
    for (size_t i = 0; i < p; i++) {
        if (i == 0 || g->code[i] != g->code[i - 1]) {
            g->start[r] = (uint32_t)i;
            g->run_code[r] = g->code[i];
            r++;
        }
        const int64_t vertex = pts ? pts[g->idx[i]] : (int64_t)g->idx[i];
        if (with_table) {
            g->point[i].vertex = vertex;
            memcpy(g->point[i].x, base + 3 * vertex, 3 * sizeof(double));
        }
        else {
            memcpy(g->coords + 3 * i, base + 3 * vertex, 3 * sizeof(double));
        }
    }
    g->start[runs] = (uint32_t)p;
    for (size_t q = 0; with_table && q < runs; q++) {  /* runs inserted in code order: near in the table */
        size_t s = oe_hash(g->run_code[q], g->mask);
        while (g->table[s].key != OE_EMPTY) {
            s = (s + 1) & g->mask;
        }
        g->table[s].key = g->run_code[q];
        g->table[s].run = ((uint64_t)g->start[q + 1] << 32) | (uint64_t)g->start[q];
    }
    free(g->code);                                   /* the runs' codes are kept; the points' are not needed */
    g->code = NULL;
    return 0;
}

typedef struct {
    int64_t *edge, *point;
    size_t count, capacity;
} OePairs;

static int
oe_push(OePairs *pairs, int64_t edge, int64_t point)
{
    if (pairs->count == pairs->capacity) {
        size_t bigger = pairs->capacity ? 2 * pairs->capacity : 1024;
        int64_t *e = (int64_t *)realloc(pairs->edge, bigger * sizeof(int64_t));
        if (e == NULL) {
            return -1;
        }
        pairs->edge = e;
        int64_t *q = (int64_t *)realloc(pairs->point, bigger * sizeof(int64_t));
        if (q == NULL) {
            return -1;
        }
        pairs->point = q;
        pairs->capacity = bigger;
    }
    pairs->edge[pairs->count] = edge;
    pairs->point[pairs->count] = point;
    pairs->count++;
    return 0;
}

/* The candidates of one edge (its index i, its rank `mark` + 1 in the stamps) appended to `pairs`. */
static int
oe_edge_pairs(const OeGrid *g, const double *v, int64_t ia, int64_t ib, int64_t i, double rtol, double gap,
              OePairs *pairs)
{
    const double cell = g->cell;
    const double *A = v + 3 * ia, *B = v + 3 * ib;
    const double d0 = B[0] - A[0], d1 = B[1] - A[1], d2 = B[2] - A[2];
    const double len = oe_norm(d0, d1, d2);
    const double len2 = len * len > DBL_MIN ? len * len : DBL_MIN;
    double scale = cell;
    for (int c = 0; c < 3; c++) {
        scale = fabs(A[c]) > scale ? fabs(A[c]) : scale;
        scale = fabs(B[c]) > scale ? fabs(B[c]) : scale;
    }
    const double slop = 64.0 * DBL_EPSILON * (len + scale);
    /* every pair passing lies within this distance of the segment */
    const double r = (gap > rtol * len ? gap : rtol * len) + slop + 1e-12 * scale;
    const double gap2 = gap * gap, slop2 = slop * slop, rtol2 = 4.0 * rtol * rtol;
    /* the edge's box widened by r: a pair the callers accept (within gap, or within rtol of the nearer end's
     * distance <= rtol len / 2, of a point of the segment, to round-off) lies in it; most points of the cells
     * visited (a soup's copies of the ends, jittered) do not, and are set aside by six comparisons */
    double box_lo[3], box_hi[3];
    for (int c = 0; c < 3; c++) {
        box_lo[c] = (A[c] < B[c] ? A[c] : B[c]) - r;
        box_hi[c] = (A[c] < B[c] ? B[c] : A[c]) + r;
    }
    const double pieces_d = ceil(2.0 * len / cell);
    const int64_t pieces = pieces_d < 1.0 ? 1 : (int64_t)pieces_d;
    int64_t prev_lo[3] = {1, 1, 1}, prev_hi[3] = {0, 0, 0};     /* the previous piece's cells (none yet) */
    for (int64_t s = 0; s < pieces; s++) {
        double p0[3], p1[3];
        const double t0 = (double)s / (double)pieces, t1 = (double)(s + 1) / (double)pieces;
        p0[0] = s == 0 ? A[0] : A[0] + t0 * d0;
        p0[1] = s == 0 ? A[1] : A[1] + t0 * d1;
        p0[2] = s == 0 ? A[2] : A[2] + t0 * d2;
        p1[0] = s + 1 == pieces ? B[0] : A[0] + t1 * d0;
        p1[1] = s + 1 == pieces ? B[1] : A[1] + t1 * d1;
        p1[2] = s + 1 == pieces ? B[2] : A[2] + t1 * d2;
        int64_t c_lo[3], c_hi[3];
        int empty = 0;
        for (int c = 0; c < 3; c++) {
            double mn = p0[c] < p1[c] ? p0[c] : p1[c], mx = p0[c] < p1[c] ? p1[c] : p0[c];
            c_lo[c] = oe_cell(mn - r, g->lo[c], cell);
            c_hi[c] = oe_cell(mx + r, g->lo[c], cell);
            c_lo[c] = c_lo[c] < 0 ? 0 : c_lo[c];
            c_hi[c] = c_hi[c] > g->top[c] ? g->top[c] : c_hi[c];
            empty |= c_lo[c] > c_hi[c];
        }
        if (empty) {
            prev_lo[0] = 1;                                   /* (no cell met by this piece's box) */
            prev_hi[0] = 0;
            continue;
        }
        for (int64_t ix = c_lo[0]; ix <= c_hi[0]; ix++) {
            for (int64_t iy = c_lo[1]; iy <= c_hi[1]; iy++) {
                for (int64_t iz = c_lo[2]; iz <= c_hi[2]; iz++) {
                    if (ix >= prev_lo[0] && ix <= prev_hi[0] && iy >= prev_lo[1] && iy <= prev_hi[1] &&
                        iz >= prev_lo[2] && iz <= prev_hi[2]) {
                        continue;                             /* visited for the previous piece */
                    }
                    const uint64_t span = oe_find(g->table, g->mask, oe_code(ix, iy, iz));
                    if (span == OE_EMPTY) {
                        continue;
                    }
                    const int64_t first = (int64_t)(span & 0xffffffffULL), stop = (int64_t)(span >> 32);
                    for (int64_t j = first; j < stop; j++) {
                        const int64_t im = g->point[j].vertex;
                        if (im == ia || im == ib) {
                            continue;
                        }
                        const double *M = g->point[j].x;
                        if ((M[0] < box_lo[0]) | (M[0] > box_hi[0]) | (M[1] < box_lo[1]) | (M[1] > box_hi[1]) |
                            (M[2] < box_lo[2]) | (M[2] > box_hi[2])) {
                            continue;
                        }
                        const double w0 = M[0] - A[0], w1 = M[1] - A[1], w2 = M[2] - A[2];
                        const double b0 = M[0] - B[0], b1 = M[1] - B[1], b2 = M[2] - B[2];
                        /* a copy of an end (exactly equal coordinates: x - y == 0 only when x == y) is on no
                         * edge's interior: both callers reject it (distance 0 from the nearer end) */
                        if ((w0 == 0.0 && w1 == 0.0 && w2 == 0.0) || (b0 == 0.0 && b1 == 0.0 && b2 == 0.0)) {
                            continue;
                        }
                        const double dot = (w0 * d0 + w1 * d1) + w2 * d2;
                        if (!(dot > -1e-12 * len2 && dot < (1.0 + 1e-12) * len2)) {
                            continue;
                        }
                        const double t = dot / len2;
                        const double e0 = M[0] - (A[0] + t * d0), e1 = M[1] - (A[1] + t * d1),
                                     e2 = M[2] - (A[2] + t * d2);
                        const double dist2 = (e0 * e0 + e1 * e1) + e2 * e2;
                        const double ta2 = (w0 * w0 + w1 * w1) + w2 * w2;
                        const double tb2 = (b0 * b0 + b1 * b1) + b2 * b2;
                        const double near2 = rtol2 * (ta2 < tb2 ? ta2 : tb2);
                        /* (x + y)^2 <= 2 x^2 + 2 y^2: dist <= max(gap, 2 rtol near) + slop implies this */
                        if (dist2 > 2.0 * (gap2 > near2 ? gap2 : near2) + 2.0 * slop2) {
                            continue;
                        }
                        if (oe_push(pairs, i, im) < 0) {
                            return -1;
                        }
                    }
                }
            }
        }
        memcpy(prev_lo, c_lo, sizeof(prev_lo));
        memcpy(prev_hi, c_hi, sizeof(prev_hi));
    }
    return 0;
}

/* Edges (in the sorted order) handed out in blocks of this many to whichever thread is free. */
#define OE_EDGE_BLOCK 4096
/* Fewer edges than this run on one thread. */
#define OE_THREAD_MIN_EDGES 65536

typedef struct {
    const OeGrid *grid;
    const double *v;
    const int64_t *e;
    const uint32_t *order;        /* the edges in the Morton order of their first end's cell */
    size_t k;
    double rtol, gap;
    OePairs *part;                /* one list of pairs per thread */
    int failed[MAX_THREADS];
    int32_t ticket;
} OeEdgeTask;

static void
oe_edge_task(void *ctx, int t, int nt)
{
    OeEdgeTask *task = (OeEdgeTask *)ctx;
    (void)nt;
    const size_t k = task->k;
    const uint32_t *order = task->order;
    const int64_t *e = task->e;
    const double *v = task->v;
    for (;;) {
        const size_t first = (size_t)next_ticket(&task->ticket) * OE_EDGE_BLOCK;
        if (first >= k || task->failed[t]) {
            return;
        }
        const size_t stop = first + OE_EDGE_BLOCK < k ? first + OE_EDGE_BLOCK : k;
        for (size_t r = first; r < stop; r++) {
            /* the edges and their ends are read in an order of their own: fetched ahead */
            if (r + 16 < stop) {
                oe_prefetch(e + 2 * (size_t)order[r + 16]);
            }
            if (r + 8 < stop) {
                const int64_t *ahead = e + 2 * (size_t)order[r + 8];
                oe_prefetch(v + 3 * ahead[0]);
                oe_prefetch(v + 3 * ahead[1]);
            }
            const int64_t i = order[r];
            if (oe_edge_pairs(task->grid, v, e[2 * i], e[2 * i + 1], i, task->rtol, task->gap, &task->part[t]) < 0) {
                task->failed[t] = 1;
                return;
            }
        }
    }
}

static PyObject *
accel_edge_point_candidates(PyObject *self, PyObject *args)
{
    PyObject *vert_obj, *edges_obj, *points_obj;
    double cell, rtol, gap;
    int threads = 1;
    if (!PyArg_ParseTuple(args, "OOOddd|i", &vert_obj, &edges_obj, &points_obj, &cell, &rtol, &gap, &threads)) {
        return NULL;
    }
    Py_buffer views[3];
    int got = 0;
    PyObject *result = NULL;
    OeGrid grid;
    memset(&grid, 0, sizeof(grid));
    OePairs pairs = {NULL, NULL, 0, 0};
    OePairs part[MAX_THREADS];
    memset(part, 0, sizeof(part));
    uint32_t *eidx = NULL, *eidx2 = NULL;
    uint64_t *ecode = NULL, *ecode2 = NULL;
    int64_t *out_e = NULL, *out_m = NULL, *per_edge = NULL;
    if (!(cell > 0.0) || !isfinite(cell) || !(rtol >= 0.0) || !isfinite(rtol) || !(gap >= 0.0) || !isfinite(gap)) {
        PyErr_Format(PyExc_ValueError, "Expected a finite cell > 0, rtol >= 0 and gap >= 0, got %g, %g and %g",
                     cell, rtol, gap);
        return NULL;
    }
    if (PyObject_GetBuffer(vert_obj, &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        goto done;
    }
    got++;
    if (PyObject_GetBuffer(edges_obj, &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        goto done;
    }
    got++;
    if (PyObject_GetBuffer(points_obj, &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        goto done;
    }
    got++;
    Py_buffer *vv = &views[0], *ev = &views[1], *pv = &views[2];
    if (native_code(vv->format) != 'd' || vv->itemsize != 8 || vv->ndim != 2 || vv->shape[1] != 3) {
        PyErr_SetString(PyExc_ValueError, "Expected `vertices` as a C-contiguous (n, 3) float64 array");
        goto done;
    }
    if (signed_int_size(ev) != 8 || ev->ndim != 2 || ev->shape[1] != 2) {
        PyErr_SetString(PyExc_ValueError, "Expected `edges` as a C-contiguous (k, 2) int64 array");
        goto done;
    }
    if (signed_int_size(pv) != 8 || pv->ndim != 1) {
        PyErr_SetString(PyExc_ValueError, "Expected `points` as a C-contiguous (p,) int64 array");
        goto done;
    }
    const double *v = (const double *)vv->buf;
    const int64_t *e = (const int64_t *)ev->buf;
    const int64_t *pts = (const int64_t *)pv->buf;
    const int64_t n = (int64_t)vv->shape[0];
    const size_t k = (size_t)ev->shape[0], p = (size_t)pv->shape[0];
    if (check_indices(e, 8, 2 * k, n) < 0 || check_indices(pts, 8, p, n) < 0) {
        goto done;
    }
    if (p == 0 || k == 0) {
        goto finish;
    }
    if (p >= (size_t)UINT32_MAX || k >= (size_t)UINT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "Expected fewer than 2**32 points and edges");
        goto done;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY};
    for (size_t i = 0; i < p; i++) {
        const double *q = v + 3 * pts[i];
        for (int c = 0; c < 3; c++) {
            if (!isfinite(q[c])) {
                PyErr_SetString(PyExc_ValueError, "Expected finite vertex coordinates");
                goto done;
            }
            lo[c] = q[c] < lo[c] ? q[c] : lo[c];
        }
    }
    int built = oe_grid_build(&grid, v, pts, p, lo, cell, 1);
    if (built == -2) {
        PyErr_Format(PyExc_ValueError, "Expected a cell of at least 2**-%d of the extent, got %g", OE_BITS, cell);
        goto done;
    }
    if (built < 0) {
        PyErr_NoMemory();
        goto done;
    }
    /* the edges in the Morton order of their first end's cell, so that consecutive edges visit nearby cells */
    ecode = (uint64_t *)malloc(k * sizeof(uint64_t));
    ecode2 = (uint64_t *)malloc(k * sizeof(uint64_t));
    eidx = (uint32_t *)malloc(k * sizeof(uint32_t));
    eidx2 = (uint32_t *)malloc(k * sizeof(uint32_t));
    if (ecode == NULL || ecode2 == NULL || eidx == NULL || eidx2 == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    for (size_t i = 0; i < k; i++) {
        const double *A = v + 3 * e[2 * i];
        int64_t c[3];
        for (int a = 0; a < 3; a++) {
            double q = floor((A[a] - lo[a]) / cell);        /* an end outside the points' box: clamped */
            c[a] = q < 0.0 ? 0 : (q > (double)(OE_MAXCELL - 1) ? OE_MAXCELL - 1 : (int64_t)q);
        }
        ecode[i] = oe_code(c[0], c[1], c[2]);
        eidx[i] = (uint32_t)i;
    }
    if (oe_radix_sort(&ecode, &eidx, &ecode2, &eidx2, k) < 0) {
        PyErr_NoMemory();
        goto done;
    }
    free(ecode);                                     /* only the order is needed from here on */
    free(ecode2);
    free(eidx2);
    ecode = ecode2 = NULL;
    eidx2 = NULL;
    const int nt = thread_count(threads, k, OE_THREAD_MIN_EDGES);
    OeEdgeTask task = {&grid, v, e, eidx, k, rtol, gap, part, {0}, 0};
    Py_BEGIN_ALLOW_THREADS
    run_parallel(nt, oe_edge_task, &task);
    Py_END_ALLOW_THREADS
    int failed = 0;
    for (int t = 0; t < nt; t++) {
        failed |= task.failed[t];
    }
    if (failed) {
        PyErr_NoMemory();
        goto done;
    }
    /* by edge, as the callers expect (a counting sort; the points of one edge in the order found: each edge is
     * searched by one thread, so the order does not depend on the threads) */
    size_t total = 0;
    for (int t = 0; t < nt; t++) {
        total += part[t].count;
    }
    per_edge = (int64_t *)calloc(k + 1, sizeof(int64_t));
    out_e = (int64_t *)malloc((total ? total : 1) * sizeof(int64_t));
    out_m = (int64_t *)malloc((total ? total : 1) * sizeof(int64_t));
    if (per_edge == NULL || out_e == NULL || out_m == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    for (int t = 0; t < nt; t++) {
        for (size_t j = 0; j < part[t].count; j++) {
            per_edge[part[t].edge[j] + 1]++;
        }
    }
    for (size_t i = 0; i < k; i++) {
        per_edge[i + 1] += per_edge[i];
    }
    for (int t = 0; t < nt; t++) {
        for (size_t j = 0; j < part[t].count; j++) {
            int64_t to = per_edge[part[t].edge[j]]++;
            out_e[to] = part[t].edge[j];
            out_m[to] = part[t].point[j];
        }
    }
    pairs.count = total;
    free(pairs.edge);
    free(pairs.point);
    pairs.edge = out_e;
    pairs.point = out_m;
    out_e = out_m = NULL;
finish:
    {
        PyObject *pe = PyBytes_FromStringAndSize((const char *)pairs.edge, (Py_ssize_t)(pairs.count * sizeof(int64_t)));
        PyObject *pm = PyBytes_FromStringAndSize((const char *)pairs.point, (Py_ssize_t)(pairs.count * sizeof(int64_t)));
        if (pe && pm) {
            result = Py_BuildValue("(OO)", pe, pm);
        }
        Py_XDECREF(pe);
        Py_XDECREF(pm);
    }
done:
    for (int i = 0; i < got; i++) {
        PyBuffer_Release(&views[i]);
    }
    oe_grid_free(&grid);
    free(ecode);
    free(ecode2);
    free(eidx);
    free(eidx2);
    free(per_edge);
    free(out_e);
    free(out_m);
    free(pairs.edge);
    free(pairs.point);
    for (int t = 0; t < MAX_THREADS; t++) {
        free(part[t].edge);
        free(part[t].point);
    }
    return result;
}

/* ------------------------------------------------------------------------------------------------------
 * 9b. close_groups -- the groups of points closer than a tolerance, transitively (mesh/merge.py)
 *
 * The connected components of the graph joining points p, q with |p - q|^2 <= tol^2 (the square evaluated as
 * (dx dx + dy dy) + dz dz, as merge._groups does with numpy), each point given the lowest input index of its
 * group.  The points are bucketed into cubic cells of side h = tol / 2 (1 + 1e-9), sorted by the Morton code
 * of their cell (section 9's grid): two points of one cell are closer than h sqrt(3) < tol, so a cell is one
 * group at once; each occupied cell is compared with the occupied cells after it in code order that meet the
 * box of its points widened by tol (a pair within tol lies in such a pair of cells), point by point until one
 * pair is within tol (a union-find over the cells; nothing is compared twice once two cells are joined).
 * The soup of a 1.3M-face mesh (3.9M points, each corner's copies a hair apart) is ~1M cells of a few points.
 * ------------------------------------------------------------------------------------------------------ */

static inline uint32_t
oe_root(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("fp-contract=off")))
#endif
static inline int
oe_cells_meet(const OeGrid *g, int64_t a, int64_t b, double tol2)
{
    for (uint32_t i = g->start[a]; i < g->start[a + 1]; i++) {
        const double *P = g->coords + 3 * (size_t)i;
        for (uint32_t j = g->start[b]; j < g->start[b + 1]; j++) {
            const double *Q = g->coords + 3 * (size_t)j;
            const double x = P[0] - Q[0], y = P[1] - Q[1], z = P[2] - Q[2];
            if ((x * x + y * y) + z * z <= tol2) {
                return 1;
            }
        }
    }
    return 0;
}

static PyObject *
accel_close_groups(PyObject *self, PyObject *args)
{
    PyObject *points_obj;
    double tol;
    if (!PyArg_ParseTuple(args, "Od", &points_obj, &tol)) {
        return NULL;
    }
    if (!(tol > 0.0) || !isfinite(tol)) {
        PyErr_Format(PyExc_ValueError, "Expected a finite tolerance > 0, got %g", tol);
        return NULL;
    }
    Py_buffer view;
    if (PyObject_GetBuffer(points_obj, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        return NULL;
    }
    PyObject *result = NULL;
    OeGrid grid;
    memset(&grid, 0, sizeof(grid));
    uint32_t *parent = NULL;
    int64_t *lowest = NULL, *out = NULL;
    OeSlot *blocks = NULL;
    if (native_code(view.format) != 'd' || view.itemsize != 8 || view.ndim != 2 || view.shape[1] != 3) {
        PyErr_SetString(PyExc_ValueError, "Expected `points` as a C-contiguous (k, 3) float64 array");
        goto done;
    }
    const double *pts = (const double *)view.buf;
    const size_t k = (size_t)view.shape[0];
    if (k >= (size_t)UINT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "Expected fewer than 2**32 points");
        goto done;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY};
    for (size_t i = 0; i < 3 * k; i++) {
        if (!isfinite(pts[i])) {
            PyErr_SetString(PyExc_ValueError, "Expected finite point coordinates");
            goto done;
        }
        lo[i % 3] = pts[i] < lo[i % 3] ? pts[i] : lo[i % 3];
    }
    const double h = 0.5 * tol * (1.0 + 1e-9);
    int built = oe_grid_build(&grid, pts, NULL, k, lo, h, 0);
    if (built == -2) {
        result = Py_None;                                  /* the grid does not fit 21 bits: the caller's path */
        Py_INCREF(result);
        goto done;
    }
    out = (int64_t *)malloc((k ? k : 1) * sizeof(int64_t));
    parent = (uint32_t *)malloc((grid.runs ? grid.runs : 1) * sizeof(uint32_t));
    lowest = (int64_t *)malloc((grid.runs ? grid.runs : 1) * sizeof(int64_t));
    if (built < 0 || out == NULL || parent == NULL || lowest == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    /* the blocks of 8^3 cells (side 4 tol): the runs of a block are consecutive in code order */
    /* blocks of 32^3 cells (side 16 tol, the codes sharing all but their 15 lowest bits): the runs of a block
     * are consecutive in code order; a cell's own block is scanned from the cell on, and the table of blocks
     * is read only for the neighbour blocks its widened box reaches (a few per cent of a soup's cells) */
    size_t nblocks = 0;
    for (size_t r = 0; r < grid.runs; r++) {
        nblocks += r == 0 || grid.run_code[r] >> OE_BLOCK_BITS != grid.run_code[r - 1] >> OE_BLOCK_BITS;
    }
    size_t bsize = 1024;
    while (bsize < 2 * nblocks) {
        bsize *= 2;
    }
    const size_t bmask = bsize - 1;
    blocks = (OeSlot *)malloc(bsize * sizeof(OeSlot));
    if (blocks == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    Py_BEGIN_ALLOW_THREADS
    for (size_t s = 0; s < bsize; s++) {
        blocks[s].key = OE_EMPTY;
    }
    for (size_t r = 0; r < grid.runs; r++) {
        parent[r] = (uint32_t)r;
        const uint64_t block = grid.run_code[r] >> OE_BLOCK_BITS;
        if (r == 0 || block != grid.run_code[r - 1] >> OE_BLOCK_BITS) {
            size_t s = (size_t)oe_mix(block) & bmask;
            while (blocks[s].key != OE_EMPTY) {
                s = (s + 1) & bmask;
            }
            blocks[s].key = block;
            blocks[s].run = r;
        }
    }
    const double tol2 = tol * tol;
    const int64_t side = (int64_t)1 << (OE_BLOCK_BITS / 3);
    for (size_t a = 0; a < grid.runs; a++) {
        double bmin[3], bmax[3];
        for (int c = 0; c < 3; c++) {
            bmin[c] = INFINITY;
            bmax[c] = -INFINITY;
        }
        for (uint32_t i = grid.start[a]; i < grid.start[a + 1]; i++) {
            for (int c = 0; c < 3; c++) {
                const double x = grid.coords[3 * (size_t)i + c];
                bmin[c] = x < bmin[c] ? x : bmin[c];
                bmax[c] = x > bmax[c] ? x : bmax[c];
            }
        }
        int64_t c_lo[3], c_hi[3];
        for (int c = 0; c < 3; c++) {
            /* widened by a little more than the rounding of x - lo and of the division */
            const double w = tol * (1.0 + 1e-9) + 8.0 * DBL_EPSILON * (fabs(bmin[c]) + fabs(bmax[c]) + fabs(lo[c]));
            double q0 = floor((bmin[c] - w - lo[c]) / h), q1 = floor((bmax[c] + w - lo[c]) / h);
            c_lo[c] = q0 < 0.0 ? 0 : (int64_t)q0;
            c_hi[c] = q1 > (double)grid.top[c] ? grid.top[c] : (int64_t)q1;
        }
        const uint64_t own = grid.run_code[a], own_block = own >> OE_BLOCK_BITS;
        for (int64_t bx = c_lo[0] / side; bx <= c_hi[0] / side; bx++) {
            for (int64_t by = c_lo[1] / side; by <= c_hi[1] / side; by++) {
                for (int64_t bz = c_lo[2] / side; bz <= c_hi[2] / side; bz++) {
                    const uint64_t block = oe_code(bx, by, bz);
                    if (block < own_block) {
                        continue;                            /* every cell there precedes this one */
                    }
                    /* the part of the box in this block: its codes lie between those of its corners */
                    const int64_t b0[3] = {bx * side, by * side, bz * side};
                    int64_t s_lo[3], s_hi[3];
                    for (int c = 0; c < 3; c++) {
                        s_lo[c] = c_lo[c] > b0[c] ? c_lo[c] : b0[c];
                        s_hi[c] = c_hi[c] < b0[c] + side - 1 ? c_hi[c] : b0[c] + side - 1;
                    }
                    const uint64_t code_lo = oe_code(s_lo[0], s_lo[1], s_lo[2]);
                    const uint64_t code_hi = oe_code(s_hi[0], s_hi[1], s_hi[2]);
                    if (code_hi <= own) {
                        continue;
                    }
                    size_t b = a + 1;
                    if (block != own_block) {
                        size_t s = (size_t)oe_mix(block) & bmask;
                        while (blocks[s].key != OE_EMPTY && blocks[s].key != block) {
                            s = (s + 1) & bmask;
                        }
                        if (blocks[s].key == OE_EMPTY) {
                            continue;
                        }
                        b = (size_t)blocks[s].run;
                    }
                    for (; b < grid.runs && grid.run_code[b] <= code_hi; b++) {
                        const uint64_t code = grid.run_code[b];
                        if (code < code_lo) {
                            continue;
                        }
                        const int64_t ix = oe_compact(code), iy = oe_compact(code >> 1), iz = oe_compact(code >> 2);
                        if (ix < c_lo[0] || ix > c_hi[0] || iy < c_lo[1] || iy > c_hi[1] || iz < c_lo[2] ||
                            iz > c_hi[2]) {
                            continue;
                        }
                        uint32_t ra = oe_root(parent, (uint32_t)a), rb = oe_root(parent, (uint32_t)b);
                        if (ra != rb && oe_cells_meet(&grid, (int64_t)a, (int64_t)b, tol2)) {
                            parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
                        }
                    }
                }
            }
        }
    }
    for (size_t r = 0; r < grid.runs; r++) {
        lowest[r] = (int64_t)k;
    }
    for (size_t r = 0; r < grid.runs; r++) {
        const uint32_t root = oe_root(parent, (uint32_t)r);
        for (uint32_t i = grid.start[r]; i < grid.start[r + 1]; i++) {
            lowest[root] = (int64_t)grid.idx[i] < lowest[root] ? (int64_t)grid.idx[i] : lowest[root];
        }
    }
    for (size_t r = 0; r < grid.runs; r++) {
        const int64_t low = lowest[oe_root(parent, (uint32_t)r)];
        for (uint32_t i = grid.start[r]; i < grid.start[r + 1]; i++) {
            out[grid.idx[i]] = low;
        }
    }
    Py_END_ALLOW_THREADS
    result = PyBytes_FromStringAndSize((const char *)out, (Py_ssize_t)(k * sizeof(int64_t)));
done:
    PyBuffer_Release(&view);
    oe_grid_free(&grid);
    free(parent);
    free(lowest);
    free(out);
    free(blocks);
    return result;
}

/* ======================================================================================================
 * 10. surface_cells -- every cell a surface meets, by clipping each triangle to the grid's slabs and rows
 *     (mesh/grid_estimate.py, _surface_cells)
 *
 * The twin of grid_estimate._clipped_cells, bit for bit (the same operations in the same order).  In grid units
 * u = (p - origin) / h (cell (i, j, k) is the closed box [i, i+1] x [j, j+1] x [k, k+1]), triangle f is clipped
 * (Sutherland-Hodgman) to each slab i - eps <= u0 <= i + 1 + eps it reaches, the polygon left to each row
 * j - eps <= u1 <= j + 1 + eps, and the cells floor(zmin - eps) .. floor(zmax + eps) of the row's polygon
 * (zmin, zmax its least and greatest u2) are marked in `out` (bytes of the flat grid, C order).  The first and
 * last slab, row and cell of each axis reach to infinity (a point off the grid marks the cell it is clamped to).
 * eps = 2^-40 (1 + the largest |u| of the triangle): every computed vertex lies within ~20 units in the last
 * place of that magnitude of the exact clip's per clip (an intersection is P + t (Q - P), t in [0, 1] rounded
 * three times), under 2^-46 (1 + |u|) after the four clips, so every cell whose closed box meets the triangle
 * is marked, and a cell that is marked comes within 2^-39 (1 + |u|) cells of it.  Work: the slabs and rows
 * the triangle crosses plus the cells marked (not the triangle's length squared, as the samples of before).
 * ====================================================================================================== */

#define SC_MAX 16       /* vertices of a clipped polygon: at most n + n/2 from n (each run outside drops one) */

/* Clip polygon p (n vertices) to u[axis] >= bound (above != 0) or u[axis] <= bound, into q; returns its count. */
static int
sc_clip(const double (*p)[3], int n, double (*q)[3], int axis, double bound, int above)
{
    int out = 0;
    for (int k = 0; k < n; k++) {
        const double *P = p[k], *Q = p[k + 1 < n ? k + 1 : 0];
        const int in_p = above ? P[axis] >= bound : P[axis] <= bound;
        const int in_q = above ? Q[axis] >= bound : Q[axis] <= bound;
        if (in_p) {
            q[out][0] = P[0];
            q[out][1] = P[1];
            q[out][2] = P[2];
            out++;
        }
        if (in_p != in_q) {
            const double t = (bound - P[axis]) / (Q[axis] - P[axis]);
            for (int c = 0; c < 3; c++) {
                q[out][c] = c == axis ? bound : P[c] + t * (Q[c] - P[c]);
            }
            out++;
        }
    }
    return out;
}

/* The cell range [first, last] along an axis of `cells` cells of the values lo .. hi (eps already applied). */
static void
sc_range(double lo, double hi, long long cells, long long *first, long long *last)
{
    const double a = floor(lo), b = floor(hi);
    const double top = (double)(cells - 1);
    *first = a < 0.0 ? 0 : (a > top ? cells - 1 : (long long)a);
    *last = b < 0.0 ? 0 : (b > top ? cells - 1 : (long long)b);
}

static PyObject *
accel_surface_cells(PyObject *self, PyObject *args)
{
    PyObject *vert_obj, *faces_obj, *out_obj;
    double o0, o1, o2, h;
    long long n0, n1, n2;
    if (!PyArg_ParseTuple(args, "OO(ddd)d(LLL)O", &vert_obj, &faces_obj, &o0, &o1, &o2, &h, &n0, &n1, &n2,
                          &out_obj)) {
        return NULL;
    }
    if (!(h > 0.0) || !isfinite(h) || n0 < 1 || n1 < 1 || n2 < 1) {
        PyErr_Format(PyExc_ValueError, "Expected a cell h > 0 and dims >= 1, got %g and (%lld, %lld, %lld)", h,
                     n0, n1, n2);
        return NULL;
    }
    Py_buffer views[3];
    int got = 0;
    PyObject *result = NULL;
    Py_ssize_t m;
    int size;
    if (PyObject_GetBuffer(vert_obj, &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        goto done;
    }
    got++;
    if (get_faces(faces_obj, &views[got], &m, &size) < 0) {
        goto done;
    }
    got++;
    if (PyObject_GetBuffer(out_obj, &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        goto done;
    }
    got++;
    Py_buffer *vv = &views[0], *fv = &views[1], *ov = &views[2];
    if (native_code(vv->format) != 'd' || vv->itemsize != 8 || vv->ndim != 2 || vv->shape[1] != 3) {
        PyErr_SetString(PyExc_ValueError, "Expected `vertices` as a C-contiguous (n, 3) float64 array");
        goto done;
    }
    if (ov->itemsize != 1 || ov->ndim != 1 || (long long)ov->shape[0] != n0 * n1 * n2) {
        PyErr_SetString(PyExc_ValueError, "Expected `out` as a writable C-contiguous byte array of prod(dims)");
        goto done;
    }
    if (check_indices(fv->buf, size, 3 * (size_t)m, (int64_t)vv->shape[0]) < 0) {
        goto done;
    }
    Py_ssize_t bad_face = -1;
    {
        const double *v = (const double *)vv->buf;
        uint8_t *out = (uint8_t *)ov->buf;
        const double origin[3] = {o0, o1, o2};
        const long long dims[3] = {n0, n1, n2};
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t f = 0; f < m; f++) {
            double tri[3][3], slab[SC_MAX][3], half[SC_MAX][3], row[SC_MAX][3];
            double most = 0.0;
            for (int k = 0; k < 3; k++) {
                const double *p = v + 3 * index_at(fv->buf, size, 3 * (size_t)f + (size_t)k);
                for (int c = 0; c < 3; c++) {
                    tri[k][c] = (p[c] - origin[c]) / h;
                    most = fabs(tri[k][c]) > most ? fabs(tri[k][c]) : most;
                }
            }
            if (!isfinite(most)) {
                bad_face = f;               /* a corner not finite, or (p - origin) / h overflowed */
                break;
            }
            const double eps = ldexp(1.0 + most, -40);
            double lo0 = tri[0][0], hi0 = tri[0][0];
            for (int k = 1; k < 3; k++) {
                lo0 = tri[k][0] < lo0 ? tri[k][0] : lo0;
                hi0 = tri[k][0] > hi0 ? tri[k][0] : hi0;
            }
            long long i0, i1;
            sc_range(lo0 - eps, hi0 + eps, dims[0], &i0, &i1);
            for (long long i = i0; i <= i1; i++) {
                int ns = 3;
                const double (*cur)[3] = (const double (*)[3])tri;
                if (i > 0) {
                    ns = sc_clip(cur, ns, half, 0, (double)i - eps, 1);
                    cur = (const double (*)[3])half;
                }
                if (i < dims[0] - 1 && ns > 0) {
                    ns = sc_clip(cur, ns, slab, 0, (double)(i + 1) + eps, 0);
                    cur = (const double (*)[3])slab;
                }
                if (ns == 0) {
                    continue;
                }
                double lo1 = cur[0][1], hi1 = cur[0][1];
                for (int k = 1; k < ns; k++) {
                    lo1 = cur[k][1] < lo1 ? cur[k][1] : lo1;
                    hi1 = cur[k][1] > hi1 ? cur[k][1] : hi1;
                }
                long long j0, j1;
                sc_range(lo1 - eps, hi1 + eps, dims[1], &j0, &j1);
                double part[SC_MAX][3];
                for (int k = 0; k < ns; k++) {
                    part[k][0] = cur[k][0];
                    part[k][1] = cur[k][1];
                    part[k][2] = cur[k][2];
                }
                for (long long j = j0; j <= j1; j++) {
                    int nr = ns;
                    const double (*rc)[3] = (const double (*)[3])part;
                    if (j > 0) {
                        nr = sc_clip(rc, nr, half, 1, (double)j - eps, 1);
                        rc = (const double (*)[3])half;
                    }
                    if (j < dims[1] - 1 && nr > 0) {
                        nr = sc_clip(rc, nr, row, 1, (double)(j + 1) + eps, 0);
                        rc = (const double (*)[3])row;
                    }
                    if (nr == 0) {
                        continue;
                    }
                    double lo2 = rc[0][2], hi2 = rc[0][2];
                    for (int k = 1; k < nr; k++) {
                        lo2 = rc[k][2] < lo2 ? rc[k][2] : lo2;
                        hi2 = rc[k][2] > hi2 ? rc[k][2] : hi2;
                    }
                    long long k0, k1;
                    sc_range(lo2 - eps, hi2 + eps, dims[2], &k0, &k1);
                    memset(out + (i * dims[1] + j) * dims[2] + k0, 1, (size_t)(k1 - k0 + 1));
                }
            }
        }
        Py_END_ALLOW_THREADS
    }
    if (bad_face >= 0) {
        PyErr_Format(PyExc_ValueError, "Expected finite corners in cells of the grid, got face %zd", bad_face);
        goto done;
    }
    result = Py_None;
    Py_INCREF(result);
done:
    for (int i = 0; i < got; i++) {
        PyBuffer_Release(&views[i]);
    }
    return result;
}

/* ======================================================================================================
 * 11. label_cells -- the face-connected regions of a grid of cells (mesh/grid_estimate.py)
 *
 * The regions of free cells of the winding-number grid, as scipy.ndimage.label numbers them with its default
 * structure (the 6 face neighbours): 1..count in the order of each region's first cell in C order.  One scan
 * in C order gives each cell the provisional label of its k-1 neighbour, else of its j-1, else of its i-1
 * neighbour, else a new one, and joins the labels of the neighbours met (a union-find whose root is the
 * smallest label, so each region's root is the label made at its first cell: every earlier face neighbour of
 * that cell is off the mask, or it would be in the region and earlier).  A j-1 (i-1) neighbour need not be
 * joined when the k-1 cell and the k-1 cell of that neighbour's row are both on the mask: the four are joined
 * already.  The roots are then numbered in increasing order (the order of the regions' first cells) and a
 * second scan writes the numbers.  Work: two scans of the grid; memory: the labels, 12 bytes per provisional
 * label.  The regions' cell counts come with the second scan.
 * ====================================================================================================== */

static int32_t
lc_find(int32_t *parent, int32_t a)
{
    while (parent[a] != a) {
        parent[a] = parent[parent[a]];              /* path halving */
        a = parent[a];
    }
    return a;
}

static void
lc_unite(int32_t *parent, int32_t a, int32_t b)
{
    a = lc_find(parent, a);
    b = lc_find(parent, b);
    if (a < b) {
        parent[b] = a;
    }
    else if (b < a) {
        parent[a] = b;
    }
}

static PyObject *
accel_label_cells(PyObject *self, PyObject *args)
{
    PyObject *mask_obj, *out_obj;
    long long n0, n1, n2;
    if (!PyArg_ParseTuple(args, "O(LLL)O", &mask_obj, &n0, &n1, &n2, &out_obj)) {
        return NULL;
    }
    if (n0 < 1 || n1 < 1 || n2 < 1 || n0 > INT32_MAX || n1 > INT32_MAX || n2 > INT32_MAX
        || n0 * n1 > INT32_MAX || n0 * n1 * n2 >= INT32_MAX) {
        PyErr_Format(PyExc_ValueError, "Expected dims >= 1 with fewer than 2**31 - 1 cells, got (%lld, %lld, %lld)",
                     n0, n1, n2);
        return NULL;
    }
    Py_buffer views[2];
    int got = 0;
    PyObject *result = NULL;
    int32_t *parent = NULL;
    int64_t *made = NULL, *sizes = NULL;
    if (PyObject_GetBuffer(mask_obj, &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        goto done;
    }
    got++;
    if (PyObject_GetBuffer(out_obj, &views[got], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_WRITABLE) < 0) {
        goto done;
    }
    got++;
    const long long total = n0 * n1 * n2;
    Py_buffer *mv = &views[0], *ov = &views[1];
    if (mv->itemsize != 1 || mv->ndim != 1 || (long long)mv->shape[0] != total) {
        PyErr_SetString(PyExc_ValueError, "Expected `mask` as a C-contiguous byte array of prod(dims)");
        goto done;
    }
    if (signed_int_size(ov) != 4 || ov->ndim != 1 || (long long)ov->shape[0] != total) {
        PyErr_SetString(PyExc_ValueError, "Expected `out` as a writable C-contiguous (prod(dims),) int32 array");
        goto done;
    }
    {
        const uint8_t *mask = (const uint8_t *)mv->buf;
        int32_t *out = (int32_t *)ov->buf;
        size_t capacity = 1024, next = 0;       /* provisional labels 1..next; 0 is "off the mask" */
        int failed = 0;
        long long count = 0;
        parent = (int32_t *)malloc(capacity * sizeof(int32_t));
        made = (int64_t *)malloc(capacity * sizeof(int64_t));
        if (parent == NULL || made == NULL) {
            PyErr_NoMemory();
            goto done;
        }
        parent[0] = 0;
        made[0] = -1;
        Py_BEGIN_ALLOW_THREADS
        const long long plane = n1 * n2;
        for (long long i = 0; i < n0 && !failed; i++) {
            for (long long j = 0; j < n1 && !failed; j++) {
                const long long row = (i * n1 + j) * n2;
                for (long long k = 0; k < n2; k++) {
                    const long long idx = row + k;
                    if (!mask[idx]) {
                        out[idx] = 0;
                        continue;
                    }
                    const int left = k > 0 && mask[idx - 1];
                    int32_t label = left ? out[idx - 1] : 0;
                    if (j > 0 && mask[idx - n2]) {
                        if (label == 0) {
                            label = out[idx - n2];
                        }
                        else if (!(left && mask[idx - n2 - 1])) {
                            lc_unite(parent, label, out[idx - n2]);
                        }
                    }
                    if (i > 0 && mask[idx - plane]) {
                        if (label == 0) {
                            label = out[idx - plane];
                        }
                        else if (!(left && mask[idx - plane - 1])) {
                            lc_unite(parent, label, out[idx - plane]);
                        }
                    }
                    if (label == 0) {
                        if (next + 1 >= capacity) {
                            size_t grown = 2 * capacity;
                            int32_t *p2 = (int32_t *)realloc(parent, grown * sizeof(int32_t));
                            if (p2 != NULL) {
                                parent = p2;
                            }
                            int64_t *m2 = p2 == NULL ? NULL : (int64_t *)realloc(made, grown * sizeof(int64_t));
                            if (m2 == NULL) {
                                failed = 1;
                                break;
                            }
                            made = m2;
                            capacity = grown;
                        }
                        next++;
                        parent[next] = (int32_t)next;
                        made[next] = idx;
                        label = (int32_t)next;
                    }
                    out[idx] = label;
                }
            }
        }
        if (!failed) {
            /* the roots numbered in increasing order; a label's parent is smaller, so numbered before it */
            for (size_t a = 1; a <= next; a++) {
                if (parent[a] == (int32_t)a) {
                    parent[a] = (int32_t)(++count);
                    made[count] = made[a];              /* count <= a: made[a] is read before it is overwritten */
                }
                else {
                    parent[a] = parent[parent[a]];      /* the parent's number (it was numbered already) */
                }
            }
            sizes = (int64_t *)calloc((size_t)count + 1, sizeof(int64_t));
            if (sizes == NULL) {
                failed = 1;
            }
            else {
                for (long long idx = 0; idx < total; idx++) {
                    const int32_t number = parent[out[idx]];
                    out[idx] = number;
                    sizes[number]++;
                }
            }
        }
        Py_END_ALLOW_THREADS
        if (failed) {
            PyErr_NoMemory();
            goto done;
        }
        result = Py_BuildValue("(Ly#y#)", count, (const char *)(made + 1),
                               (Py_ssize_t)(count * (long long)sizeof(int64_t)), (const char *)(sizes + 1),
                               (Py_ssize_t)(count * (long long)sizeof(int64_t)));
    }
done:
    free(parent);
    free(made);
    free(sizes);
    for (int i = 0; i < got; i++) {
        PyBuffer_Release(&views[i]);
    }
    return result;
}

/* ======================================================================================================
 * 12. certain_parts -- the sub-cells of band cells certainly in or out of a solid's core (mass/offset.py)
 *
 * The twin of offset._certain_parts's loop over the samples.  Cell i (centre c_i) has samples j with margins
 * m_ij = d(x_j) - t and closest surface points q_ij; sub-cell s has centre c_i + sub_s and gap[s, j] =
 * |c_i + sub_s - x_j| (the same for every cell).  Sub-cell s is in the core when m_ij - gap[s, j] >= rho for
 * some j; outside it when -m_ij - gap[s, j] >= rho for some j, or (`reach` nonzero, i.e. t > rho) when
 * |c_i + sub_s - q_ij|^2 <= limit = (t - rho)^2, evaluated as numpy does ((|a|^2 + 2 a.sub_s) + |sub_s|^2 with
 * a = c_i - q_ij).  `empty` is set only where `core` is not.  The expressions are numpy's but the sums may round
 * differently from its matrix product: only a sub-cell whose test lands within an ulp or two of its threshold can
 * be decided otherwise (either decision is sound to that round-off).
 * ====================================================================================================== */

static PyObject *
accel_certain_parts(PyObject *self, PyObject *args)
{
    PyObject *objs[7];
    double rho, limit;
    int reach;
    if (!PyArg_ParseTuple(args, "OOOOOddpOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &rho, &limit,
                          &reach, &objs[5], &objs[6])) {
        return NULL;
    }
    Py_buffer views[7];
    int got = 0;
    PyObject *result = NULL;
    for (int i = 0; i < 7; i++) {
        int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (i >= 5 ? PyBUF_WRITABLE : 0);
        if (PyObject_GetBuffer(objs[i], &views[i], flags) < 0) {
            goto done;
        }
        got++;
    }
    for (int i = 0; i < 5; i++) {
        if (native_code(views[i].format) != 'd' || views[i].itemsize != 8) {
            PyErr_SetString(PyExc_ValueError, "Expected centres, margins, closest, gap and sub as C-contiguous "
                            "float64 arrays");
            goto done;
        }
    }
    {
        const Py_ssize_t k = views[0].len / (3 * 8);
        const Py_ssize_t ns = views[4].len / (3 * 8);
        const Py_ssize_t nj = ns > 0 ? views[3].len / (8 * ns) : 0;
        if (views[0].len != k * 3 * 8 || views[4].len != ns * 3 * 8 || ns < 1 || nj < 1
            || views[3].len != ns * nj * 8 || views[1].len != k * nj * 8 || views[2].len != k * nj * 3 * 8
            || views[5].itemsize != 1 || views[6].itemsize != 1 || views[5].len != k * ns || views[6].len != k * ns) {
            PyErr_SetString(PyExc_ValueError, "Expected centres (k, 3), margins (k, j), closest (k, j, 3), gap (s, j), "
                            "sub (s, 3) and core, empty as writable byte arrays of k * s");
            goto done;
        }
        const double *centres = (const double *)views[0].buf, *margins = (const double *)views[1].buf;
        const double *closest = (const double *)views[2].buf, *gap = (const double *)views[3].buf;
        const double *sub = (const double *)views[4].buf;
        uint8_t *core = (uint8_t *)views[5].buf, *empty = (uint8_t *)views[6].buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t i = 0; i < k; i++) {
            const double *c = centres + 3 * i, *m = margins + nj * i, *q = closest + 3 * nj * i;
            for (Py_ssize_t s = 0; s < ns; s++) {
                const double *y = sub + 3 * s, *g = gap + nj * s;
                const double y2 = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
                int in = 0, out = 0;
                for (Py_ssize_t j = 0; j < nj && !in; j++) {
                    const double mj = m[j];
                    if (mj - g[j] >= rho) {
                        in = 1;
                        break;
                    }
                    if (!out && -mj - g[j] >= rho) {
                        out = 1;
                    }
                    if (!out && reach) {
                        const double a0 = c[0] - q[3 * j], a1 = c[1] - q[3 * j + 1], a2 = c[2] - q[3 * j + 2];
                        const double r2 = ((a0 * a0 + a1 * a1 + a2 * a2) + 2.0 * (a0 * y[0] + a1 * y[1] + a2 * y[2]))
                                          + y2;
                        if (r2 <= limit) {
                            out = 1;
                        }
                    }
                }
                core[ns * i + s] = (uint8_t)in;
                empty[ns * i + s] = (uint8_t)(out && !in);
            }
        }
        Py_END_ALLOW_THREADS
    }
    result = Py_None;
    Py_INCREF(result);
done:
    for (int i = 0; i < got; i++) {
        PyBuffer_Release(&views[i]);
    }
    return result;
}

/* ======================================================================================================
 * 13. winding_tree -- the generalized winding number by the treecode of mesh/winding.py, point by point
 *
 * The twin of winding._treecode_numpy (the reference): the same tree of face clusters (built in Python,
 * winding._Tree; passed flattened, level 0 = the leaves), the same decision per cluster seen from a point q:
 * with u = centre - q, d = |u|, r = radius, A = area,
 *     bound = 3 A r^2 / (4 pi max(d - r, 0)^4),   far  <=>  d > 2 r  and  bound <= tolerance,
 * a far cluster adds its dipole term (N.u / d^3 + (tr M - 3 e^T M e) / d^3) / (4 pi), e = u / d, and its bound;
 * a near cluster is refined into its children (2i, 2i+1 on the level below, those that exist), and a near leaf
 * adds the exact solid angle of each of its faces (Van Oosterom & Strackee, as winding._solid_angles).
 *
 * The expressions and the order of every sum are numpy's, so the values are its values bit for bit where numpy
 * evaluates them as measured on x86-64 (numpy 2.x): a 3-vector dot product (einsum) as (x0 y0 + x2 y2) + x1 y1,
 * the trace as (M00 + M11) + M22, e^T M e as the sum over i then j of (e_i M_ij) e_j in that order, d^3 and
 * (d - r)^4 by pow(), arctan2 by atan2(); the far terms summed per level in ascending cluster order (the tree is
 * walked depth first, left child first, which visits each level's clusters in that order) and the levels added
 * from the top; the leaves' solid angles summed in ascending order per block of `block` (point, leaf) pairs of
 * each chunk of `chunk` points (numpy's vectorised blocks), each block's sum divided by 4 pi and added in turn.
 * A first walk counts each point's near leaves to place those block boundaries.  Where numpy's kernels round
 * differently the values still agree to round-off, each within its own bound of the exact sum.  Each point is
 * independent of the others: the thread count changes nothing.
 *
 * Layout: `clusters` (K, 17) float64 rows [normal xyz, area, centre xyz, radius, moment M row-major 9];
 * `levels` (L + 1,) int64 the first row of each level (levels[0] = 0, levels[L] = K), level 0 the leaves;
 * `triangles` (m, 9) float64 [a xyz, b xyz, c xyz] in the tree's (Morton) order; leaf i holds faces
 * [i leaf, min((i + 1) leaf, m)).
 * ====================================================================================================== */

#define WT_ROW 17
#define WT_STACK 512
#define WT_LEVELS 64
#define WT_BLOCK 16            /* points per work ticket */
#define WT_PARTS 64            /* blocks of (point, leaf) pairs one point may span */

typedef struct {
    const double *points, *clusters, *tri;
    const int64_t *levels;
    int64_t n_levels, m, leaf, n_points, chunk, block;
    double tolerance;
    double *w, *err;
    int64_t *near_count;       /* pass 1: near leaves per point; then each point's first pair in its chunk */
    int32_t next;
    int pass;
    int overflow;              /* set when a stack would overflow (not expected: depth <= L + 8) */
} WindingTask;

static const double wt_four_pi = 4.0 * 3.14159265358979323846;

/* numpy's einsum of two 3-vectors (two lanes from +0): ((0 + x0 y0) + x2 y2) + (0 + x1 y1), which is
 * (x0 y0 + x2 y2) + x1 y1 but never -0 (the sign of a zero numerator decides a solid angle of +-2 pi) */
static inline double
wt_dot(double x0, double x1, double x2, double y0, double y1, double y2)
{
    const double p0 = x0 * y0, p1 = x1 * y1, p2 = x2 * y2;
    return ((0.0 + p0) + p2) + (0.0 + p1);
}

/* winding._solid_angles for one triangle t = [a, b, c] and point q, expression by expression */
static inline double
wt_solid_angle(const double *q, const double *t)
{
    const double ax = t[0] - q[0], ay = t[1] - q[1], az = t[2] - q[2];
    const double bx = t[3] - q[0], by = t[4] - q[1], bz = t[5] - q[2];
    const double cx = t[6] - q[0], cy = t[7] - q[1], cz = t[8] - q[2];
    const double la = sqrt(wt_dot(ax, ay, az, ax, ay, az));
    const double lb = sqrt(wt_dot(bx, by, bz, bx, by, bz));
    const double lc = sqrt(wt_dot(cx, cy, cz, cx, cy, cz));
    /* numpy.cross(b, c): b1 c2 - b2 c1, b2 c0 - b0 c2, b0 c1 - b1 c0 */
    const double x0 = by * cz - bz * cy, x1 = bz * cx - bx * cz, x2 = bx * cy - by * cx;
    const double num = wt_dot(ax, ay, az, x0, x1, x2);
    const double den = ((la * lb * lc + wt_dot(ax, ay, az, bx, by, bz) * lc) + wt_dot(ax, ay, az, cx, cy, cz) * lb)
                       + wt_dot(bx, by, bz, cx, cy, cz) * la;
    return 2.0 * atan2(num, den);
}

/* One point: pass 1 counts its near leaves into *count; pass 2 writes w and err, its (point, leaf) pairs
 * starting at index `first` of its chunk's list. */
static int
wt_point(const WindingTask *c, const double *q, int64_t *count, int64_t first, double *w_out, double *err_out)
{
    int64_t stack_level[WT_STACK], stack_index[WT_STACK];
    double far_sum[WT_LEVELS], bound_sum[WT_LEVELS];
    int top = 0;
    const int64_t L = c->n_levels;
    const int64_t n_top = c->levels[L] - c->levels[L - 1];
    const int evaluate = c->pass == 2;
    for (int64_t l = 0; l < L; l++) {
        far_sum[l] = 0.0;
        bound_sum[l] = 0.0;
    }
    for (int64_t i = n_top - 1; i >= 0; i--) {
        if (top >= WT_STACK) {
            return -1;
        }
        stack_level[top] = L - 1;
        stack_index[top] = i;
        top++;
    }
    int64_t pair = first;                       /* index of the next (point, leaf) pair in the chunk's list */
    int64_t leaves = 0;
    double parts[WT_PARTS];                     /* the leaves' sum per block, in order */
    int n_parts = 0;
    while (top > 0) {
        top--;
        const int64_t level = stack_level[top], i = stack_index[top];
        const double *row = c->clusters + WT_ROW * (c->levels[level] + i);
        const double ux = row[4] - q[0], uy = row[5] - q[1], uz = row[6] - q[2];
        const double d = sqrt(wt_dot(ux, uy, uz, ux, uy, uz));
        const double r = row[7];
        const double gap = d - r > 0.0 ? d - r : 0.0;    /* numpy.maximum(d - r, 0.0) */
        const double bound = 3.0 * row[3] * (r * r) / (wt_four_pi * pow(gap, 4.0));   /* inf or NaN at gap 0 */
        if (d > 2.0 * r && bound <= c->tolerance) {
            if (evaluate) {
                const double *M = row + 8;
                const double e[3] = {ux / d, uy / d, uz / d};
                double quad = 0.0;
                for (int a = 0; a < 3; a++) {
                    for (int b = 0; b < 3; b++) {
                        quad += (e[a] * M[3 * a + b]) * e[b];
                    }
                }
                const double d3 = pow(d, 3.0);
                const double first_order = (((M[0] + M[4]) + M[8]) - 3.0 * quad) / d3;
                far_sum[level] += (wt_dot(row[0], row[1], row[2], ux, uy, uz) / d3 + first_order) / wt_four_pi;
                bound_sum[level] += bound;
            }
        }
        else if (level > 0) {
            const int64_t below = c->levels[level] - c->levels[level - 1];
            if (top + 2 > WT_STACK) {
                return -1;
            }
            if (2 * i + 1 < below) {
                stack_level[top] = level - 1;
                stack_index[top] = 2 * i + 1;
                top++;
            }
            if (2 * i < below) {
                stack_level[top] = level - 1;
                stack_index[top] = 2 * i;
                top++;
            }
        }
        else if (!evaluate) {
            leaves++;
        }
        else {
            if (n_parts == 0 || pair % c->block == 0) {      /* the first pair, or numpy's next block */
                if (n_parts >= WT_PARTS) {
                    return -1;
                }
                parts[n_parts++] = 0.0;
            }
            const int64_t start = i * c->leaf;
            const int64_t stop = start + c->leaf < c->m ? start + c->leaf : c->m;
            double sum = parts[n_parts - 1];
            for (int64_t f = start; f < stop; f++) {
                sum += wt_solid_angle(q, c->tri + 9 * f);
            }
            parts[n_parts - 1] = sum;
            pair++;
        }
    }
    if (!evaluate) {
        *count = leaves;
        return 0;
    }
    /* numpy: w = 0, each level's far sum added from the top, then each block's leaf sum / 4 pi in turn */
    double total = 0.0, error = 0.0;
    for (int64_t l = L - 1; l >= 0; l--) {
        total += far_sum[l];
        error += bound_sum[l];
    }
    for (int k = 0; k < n_parts; k++) {
        total += parts[k] / wt_four_pi;
    }
    *w_out = total;
    *err_out = error;
    return 0;
}

static void
winding_tree_task(void *ctx, int t, int nt)
{
    WindingTask *c = (WindingTask *)ctx;
    (void)t;
    (void)nt;
    for (;;) {
        const int64_t start = (int64_t)next_ticket(&c->next) * WT_BLOCK;
        if (start >= c->n_points) {
            break;
        }
        const int64_t stop = start + WT_BLOCK < c->n_points ? start + WT_BLOCK : c->n_points;
        for (int64_t p = start; p < stop; p++) {
            if (wt_point(c, c->points + 3 * p, c->near_count + p, c->near_count[p], c->w + p, c->err + p) < 0) {
                __atomic_store_n(&c->overflow, 1, __ATOMIC_RELAXED);
            }
        }
    }
}

static PyObject *
accel_winding_tree(PyObject *self, PyObject *args)
{
    PyObject *objs[6];
    long long leaf, chunk, block;
    double tolerance;
    int threads = 1;
    if (!PyArg_ParseTuple(args, "OOOOLdLLOO|i", &objs[0], &objs[1], &objs[2], &objs[3], &leaf, &tolerance, &chunk,
                          &block, &objs[4], &objs[5], &threads)) {
        return NULL;
    }
    Py_buffer views[6];
    int got = 0;
    PyObject *result = NULL;
    int64_t *near_count = NULL;
    for (int i = 0; i < 6; i++) {
        int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (i >= 4 ? PyBUF_WRITABLE : 0);
        if (PyObject_GetBuffer(objs[i], &views[i], flags) < 0) {
            goto done;
        }
        got++;
    }
    {
        Py_buffer *pv = &views[0], *cv = &views[1], *lv = &views[2], *tv = &views[3], *wv = &views[4], *ev = &views[5];
        const int float_ok = native_code(pv->format) == 'd' && pv->itemsize == 8 && native_code(cv->format) == 'd'
                             && cv->itemsize == 8 && native_code(tv->format) == 'd' && tv->itemsize == 8
                             && native_code(wv->format) == 'd' && wv->itemsize == 8 && native_code(ev->format) == 'd'
                             && ev->itemsize == 8;
        if (!float_ok || signed_int_size(lv) != 8) {
            PyErr_SetString(PyExc_ValueError, "Expected points, clusters, triangles, w and err as C-contiguous "
                            "float64 arrays and levels as int64");
            goto done;
        }
        const int64_t n_points = (int64_t)(pv->len / 24), n_rows = (int64_t)(cv->len / (8 * WT_ROW));
        const int64_t n_bounds = (int64_t)(lv->len / 8), m = (int64_t)(tv->len / 72);
        if (pv->len != n_points * 24 || cv->len != n_rows * 8 * WT_ROW || tv->len != m * 72
            || wv->len != n_points * 8 || ev->len != n_points * 8 || n_bounds < 2 || n_bounds > WT_LEVELS + 1
            || leaf < 1 || m < 1 || chunk < 1 || block < 1) {
            PyErr_SetString(PyExc_ValueError, "Expected points (p, 3), clusters (K, 17), levels (L + 1,) with "
                            "1 <= L <= 64, triangles (m >= 1, 9), w and err (p,), leaf, chunk, block >= 1");
            goto done;
        }
        const int64_t *levels = (const int64_t *)lv->buf;
        /* the tree's shape: levels rising from 0 to K, the leaves cover the m faces, each level's clusters
           the parents of the halves below (ceil(count / 2) of the level below) */
        const int64_t n_leaves = (m + leaf - 1) / leaf;
        int shape_ok = levels[0] == 0 && levels[n_bounds - 1] == n_rows && levels[1] == n_leaves;
        for (int64_t l = 1; shape_ok && l < n_bounds - 1; l++) {
            const int64_t below = levels[l] - levels[l - 1], here = levels[l + 1] - levels[l];
            shape_ok = here >= 1 && here == (below + 1) / 2;
        }
        if (!shape_ok) {
            PyErr_SetString(PyExc_ValueError, "Expected `levels` of a binary tree over ceil(m / leaf) leaves "
                            "(each level half the one below, rounded up), ending at the clusters' count");
            goto done;
        }
        if (n_leaves / block + 2 > WT_PARTS || n_points / WT_BLOCK >= INT32_MAX) {
            PyErr_SetString(PyExc_ValueError, "Expected at most (64 - 2) blocks of leaves and fewer than 2**35 points");
            goto done;
        }
        near_count = (int64_t *)malloc((size_t)(n_points > 0 ? n_points : 1) * sizeof(int64_t));
        if (near_count == NULL) {
            PyErr_NoMemory();
            goto done;
        }
        WindingTask task;
        task.points = (const double *)pv->buf;
        task.clusters = (const double *)cv->buf;
        task.tri = (const double *)tv->buf;
        task.levels = levels;
        task.n_levels = n_bounds - 1;
        task.m = m;
        task.leaf = (int64_t)leaf;
        task.n_points = n_points;
        task.chunk = (int64_t)chunk;
        task.block = (int64_t)block;
        task.tolerance = tolerance;
        task.w = (double *)wv->buf;
        task.err = (double *)ev->buf;
        task.near_count = near_count;
        task.overflow = 0;
        const int nt = thread_count(threads, (size_t)n_points, 4 * WT_BLOCK);
        Py_BEGIN_ALLOW_THREADS
        /* pass 1: each point's near leaves; then each point's first pair within its chunk (numpy's list of
           pairs for the chunk is point by point); pass 2: the values */
        task.pass = 1;
        task.next = 0;
        run_parallel(nt, winding_tree_task, &task);
        for (int64_t s = 0; s < n_points; s += task.chunk) {
            int64_t running = 0;
            const int64_t e = s + task.chunk < n_points ? s + task.chunk : n_points;
            for (int64_t p = s; p < e; p++) {
                const int64_t here = near_count[p];
                near_count[p] = running;
                running += here;
            }
        }
        task.pass = 2;
        task.next = 0;
        if (!task.overflow) {
            run_parallel(nt, winding_tree_task, &task);
        }
        Py_END_ALLOW_THREADS
        if (task.overflow) {
            PyErr_SetString(PyExc_RuntimeError, "winding_tree: a traversal stack or the blocks of a point overflowed "
                            "(a tree deeper than expected)");
            goto done;
        }
    }
    result = Py_None;
    Py_INCREF(result);
done:
    free(near_count);
    for (int i = 0; i < got; i++) {
        PyBuffer_Release(&views[i]);
    }
    return result;
}
