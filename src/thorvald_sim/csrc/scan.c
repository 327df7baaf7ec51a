/* thorvald_sim._scan: the arithmetic around a lidar's rays, in C.
 *
 * A planar lidar's 720 rays cost pybullet about 300 us; the Python around them (the beams turned
 * into the world, the hit fractions taken out of rayTestBatch's tuples, the ranges) cost the
 * simulator node another 120 us a scan, most of it the overhead of a dozen small numpy calls on
 * caches the physics step has just flushed (the noise added to the ranges alone: two of them). These
 * two loops do the same in a few microseconds.
 * thorvald_sim.sensors.kinds.lidar uses numpy where this module is not built, with the same results
 * (test_sensors compares them).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>

static int is_double_format(const char *format)
{
    return format == NULL || strcmp(format, "d") == 0 || strcmp(format, "<d") == 0 ||
           strcmp(format, "=d") == 0 || strcmp(format, "@d") == 0;
}

static int double_buffer(PyObject *obj, Py_buffer *view, Py_ssize_t count, int writable, const char *name)
{
    int flags = PyBUF_FORMAT | PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) < 0)
        return -1;
    if (view->itemsize != (Py_ssize_t)sizeof(double) || !is_double_format(view->format) ||
        view->len < count * (Py_ssize_t)sizeof(double)) {
        PyErr_Format(PyExc_ValueError, "%s must be C-contiguous float64 with room for %zd values", name, count);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* beams(quaternion, origin, directions, range_min, range_max, starts, ends) -> number of beams
 * The beams' start and end points in the world: origin + R(quaternion) d range_min and
 * origin + R d range_max for every unit direction d (N x 3, the sensor frame). R is Bullet's
 * btMatrix3x3::setRotation of (x, y, z, w), as pybullet's getMatrixFromQuaternion. */
static PyObject *beams(PyObject *self, PyObject *args)
{
    double qx, qy, qz, qw, ox, oy, oz, range_min, range_max;
    double s, xs, ys, zs, wx, wy, wz, xx, xy, xz, yy, yz, zz, m[9];
    PyObject *directions, *starts, *ends;
    Py_buffer dv, sv, ev;
    Py_ssize_t n, i;
    const double *d;
    double *a, *b;
    (void)self;

    if (!PyArg_ParseTuple(args, "(dddd)(ddd)OddOO", &qx, &qy, &qz, &qw, &ox, &oy, &oz, &directions, &range_min,
                          &range_max, &starts, &ends))
        return NULL;
    if (double_buffer(directions, &dv, 0, 0, "directions") < 0)
        return NULL;
    n = dv.len / (Py_ssize_t)(3 * sizeof(double));
    if (double_buffer(starts, &sv, 3 * n, 1, "starts") < 0) {
        PyBuffer_Release(&dv);
        return NULL;
    }
    if (double_buffer(ends, &ev, 3 * n, 1, "ends") < 0) {
        PyBuffer_Release(&dv);
        PyBuffer_Release(&sv);
        return NULL;
    }
    s = 2.0 / (qx * qx + qy * qy + qz * qz + qw * qw);
    xs = qx * s, ys = qy * s, zs = qz * s;
    wx = qw * xs, wy = qw * ys, wz = qw * zs;
    xx = qx * xs, xy = qx * ys, xz = qx * zs;
    yy = qy * ys, yz = qy * zs, zz = qz * zs;
    m[0] = 1.0 - (yy + zz), m[1] = xy - wz, m[2] = xz + wy;
    m[3] = xy + wz, m[4] = 1.0 - (xx + zz), m[5] = yz - wx;
    m[6] = xz - wy, m[7] = yz + wx, m[8] = 1.0 - (xx + yy);
    d = (const double *)dv.buf, a = (double *)sv.buf, b = (double *)ev.buf;
    for (i = 0; i < n; i++, d += 3, a += 3, b += 3) {
        double x = m[0] * d[0] + m[1] * d[1] + m[2] * d[2];
        double y = m[3] * d[0] + m[4] * d[1] + m[5] * d[2];
        double z = m[6] * d[0] + m[7] * d[1] + m[8] * d[2];
        a[0] = ox + x * range_min, a[1] = oy + y * range_min, a[2] = oz + z * range_min;
        b[0] = ox + x * range_max, b[1] = oy + y * range_max, b[2] = oz + z * range_max;
    }
    PyBuffer_Release(&dv);
    PyBuffer_Release(&sv);
    PyBuffer_Release(&ev);
    return PyLong_FromSsize_t(n);
}

/* ranges(hits, out, range_min, range_max, noise=None, stddev=0.0) -> number of rays
 * rayTestBatch's results (object, link, fraction, position, normal), cast from range_min to
 * range_max, as ranges into out (float64): inf where the ray hit nothing (fraction 1), else
 * range_min + fraction (range_max - range_min), plus stddev noise[i] where noise (float64, one per
 * ray) is given. */
static PyObject *ranges(PyObject *self, PyObject *args)
{
    PyObject *hits, *out, *seq, *noise = Py_None;
    double range_min, range_max, stddev = 0.0;
    Py_buffer view, noise_view;
    Py_ssize_t n, i;
    PyObject **items;
    double *r, span;
    const double *z = NULL;
    (void)self;

    if (!PyArg_ParseTuple(args, "OOdd|Od", &hits, &out, &range_min, &range_max, &noise, &stddev))
        return NULL;
    seq = PySequence_Fast(hits, "ranges: hits must be a sequence of rayTestBatch results");
    if (seq == NULL)
        return NULL;
    n = PySequence_Fast_GET_SIZE(seq);
    if (double_buffer(out, &view, n, 1, "out") < 0) {
        Py_DECREF(seq);
        return NULL;
    }
    if (noise != Py_None) {
        if (double_buffer(noise, &noise_view, n, 0, "noise") < 0) {
            PyBuffer_Release(&view);
            Py_DECREF(seq);
            return NULL;
        }
        z = (const double *)noise_view.buf;
    }
    r = (double *)view.buf;
    span = range_max - range_min;
    items = PySequence_Fast_ITEMS(seq);
    for (i = 0; i < n; i++) {
        PyObject *hit = items[i];
        double f, range;
        if (!PyTuple_Check(hit) || PyTuple_GET_SIZE(hit) < 3) {
            PyErr_Format(PyExc_TypeError, "ranges: result %zd is not a rayTestBatch result", i);
            goto fail;
        }
        f = PyFloat_AsDouble(PyTuple_GET_ITEM(hit, 2));
        if (f == -1.0 && PyErr_Occurred())
            goto fail;
        if (f >= 1.0) {
            r[i] = INFINITY;
            continue;
        }
        range = range_min + f * span;
        r[i] = z ? range + stddev * z[i] : range;
    }
    if (z)
        PyBuffer_Release(&noise_view);
    PyBuffer_Release(&view);
    Py_DECREF(seq);
    return PyLong_FromSsize_t(n);

fail:
    if (z)
        PyBuffer_Release(&noise_view);
    PyBuffer_Release(&view);
    Py_DECREF(seq);
    return NULL;
}

static PyMethodDef methods[] = {
    {"beams", beams, METH_VARARGS,
     "beams(quaternion, origin, directions, range_min, range_max, starts, ends) -> n: the beams in the world"},
    {"ranges", ranges, METH_VARARGS,
     "ranges(hits, out, range_min, range_max, noise=None, stddev=0.0) -> n: rayTestBatch results to ranges in "
     "out (inf: no hit), plus stddev * noise"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_scan", NULL, -1, methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__scan(void)
{
    return PyModule_Create(&module);
}
