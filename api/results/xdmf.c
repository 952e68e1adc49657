/* xdmf.c — the XDMF 3 sidecar of a result file (contract in xdmf.h). */
#include "xdmf.h"

#include <fcntl.h>
#include <hdf5.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "h5_result.h"

/* Escape the few characters XML attributes cannot hold. */
static void xml_escape(const char *s, char *out, size_t n)
{
    size_t o = 0;
    for (; *s && o + 7 < n; s++) {
        const char *rep = *s == '&' ? "&amp;" : *s == '<' ? "&lt;" : *s == '"' ? "&quot;" : NULL;
        if (rep) {
            memcpy(out + o, rep, strlen(rep));
            o += strlen(rep);
        } else {
            out[o++] = *s;
        }
    }
    out[o] = 0;
}

/* The directory part of path, made absolute ("." when it has none). */
static int abs_dir(const char *path, char *out)
{
    char d[PATH_MAX];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(d, sizeof d, ".");
    else if (slash == path)
        snprintf(d, sizeof d, "/");
    else
        snprintf(d, sizeof d, "%.*s", (int)(slash - path), path);
    return realpath(d, out) ? 0 : -1;
}

int pk_xdmf_relative_ref(const char *h5_path, const char *xdmf_path, char *out, size_t n)
{
    char from[PATH_MAX], to[PATH_MAX];
    const char *base = strrchr(h5_path, '/');
    base = base ? base + 1 : h5_path;
    if (abs_dir(xdmf_path, from) != 0 || abs_dir(h5_path, to) != 0)
        return -1;
    /* longest common prefix ending at a directory boundary */
    size_t common = 0;
    for (size_t i = 0;; i++) {
        int end_f = from[i] == 0 || from[i] == '/', end_t = to[i] == 0 || to[i] == '/';
        if (end_f && end_t)
            common = i;
        if (from[i] != to[i] || !from[i])
            break;
    }
    size_t o = 0;
    out[0] = 0;
    for (const char *p = from + common; *p; p++) /* one ".." per directory left in from */
        if (*p == '/' && o + 4 < n) {
            memcpy(out + o, "../", 4);
            o += 3;
        }
    const char *rest = to + common;
    while (*rest == '/')
        rest++;
    int w = snprintf(out + o, n - o, "%s%s%s", rest, *rest ? "/" : "", base);
    return w < 0 || (size_t)w >= n - o ? -1 : 0;
}

/* The dimensions of the dataset at path (rank, or -1 when absent). */
static int dims_of(hid_t f, const char *path, hsize_t d[3])
{
    char part[256];
    /* every link on the way must exist before H5Dopen may look */
    for (const char *p = strchr(path + 1, '/');; p = strchr(p + 1, '/')) {
        snprintf(part, sizeof part, "%.*s", p ? (int)(p - path) : (int)strlen(path), path);
        if (H5Lexists(f, part, H5P_DEFAULT) <= 0)
            return -1;
        if (!p)
            break;
    }
    hid_t ds = H5Dopen2(f, path, H5P_DEFAULT);
    if (ds < 0)
        return -1;
    hid_t sp = H5Dget_space(ds);
    int rank = H5Sget_simple_extent_ndims(sp);
    if (rank > 3 || H5Sget_simple_extent_dims(sp, d, NULL) < 0)
        rank = -1;
    H5Sclose(sp);
    H5Dclose(ds);
    return rank;
}

/* The XDMF number type, precision and byte order of a dataset's type; -1
 * for a type the sidecar does not describe. */
static int number_type(hid_t ds, const char **type, int *prec, const char **endian)
{
    hid_t t = H5Dget_type(ds);
    H5T_class_t c = H5Tget_class(t);
    *prec = (int)H5Tget_size(t);
    *type = c == H5T_FLOAT ? "Float" : c == H5T_INTEGER ? "Int" : NULL;
    *endian = H5Tget_order(t) == H5T_ORDER_BE ? "Big" : "Little";
    H5Tclose(t);
    return *type && (*prec == 4 || *prec == 8) ? 0 : -1;
}

/* A DataItem of the whole dataset at path, with its own shape and number
 * type (what a reader finds there).  0, or -1 when it is absent. */
static int item(FILE *f, const char *ind, hid_t h, const char *ref, const char *path)
{
    hsize_t d[3];
    int rank = dims_of(h, path, d);
    hid_t ds = rank > 0 ? H5Dopen2(h, path, H5P_DEFAULT) : -1;
    const char *type, *endian;
    int prec, ok = ds >= 0 && number_type(ds, &type, &prec, &endian) == 0;
    if (ds >= 0)
        H5Dclose(ds);
    if (!ok)
        return -1;
    fprintf(f, "%s<DataItem Dimensions=\"", ind);
    for (int a = 0; a < rank; a++)
        fprintf(f, a ? " %llu" : "%llu", (unsigned long long)d[a]);
    fprintf(f, "\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">%s:%s</DataItem>\n", type,
            prec, ref, path);
    return 0;
}

/* 1 when the dataset at path is stored in one piece at a known offset. */
static int has_offset(hid_t h, const char *path)
{
    hid_t ds = H5Dopen2(h, path, H5P_DEFAULT);
    int ok = ds >= 0 && H5Dget_offset(ds) != HADDR_UNDEF;
    if (ds >= 0)
        H5Dclose(ds);
    return ok;
}

/* Row k of the dataset at path (a time-dependent element's value, [S][…]),
 * read by its bytes: ParaView's Xdmf3 reader crashes on a HyperSlab
 * (SIGSEGV in vtkXdmf3DataSet::CopyShape, ParaView 5.11) but reads a Binary
 * item at an offset of the same file, as the legacy reader does.  The row's
 * shape is the value's without its first dimension; Name says which row.
 * 0, or -1 when the dataset is absent, not contiguous (no offset) or k is
 * past its end. */
static int row_item(FILE *f, const char *ind, hid_t h, const char *ref, const char *path, hsize_t k)
{
    hsize_t d[3];
    int rank = dims_of(h, path, d);
    hid_t ds = rank >= 2 ? H5Dopen2(h, path, H5P_DEFAULT) : -1;
    const char *type, *endian;
    int prec, ok = ds >= 0 && k < d[0] && number_type(ds, &type, &prec, &endian) == 0;
    haddr_t at = ok ? H5Dget_offset(ds) : HADDR_UNDEF;
    if (ds >= 0)
        H5Dclose(ds);
    if (at == HADDR_UNDEF)
        return -1;
    unsigned long long row = (unsigned long long)prec;
    for (int a = 1; a < rank; a++)
        row *= d[a];
    fprintf(f, "%s<DataItem Name=\"%s[%llu]\" Dimensions=\"", ind, path, (unsigned long long)k);
    for (int a = 1; a < rank; a++)
        fprintf(f, a > 1 ? " %llu" : "%llu", (unsigned long long)d[a]);
    fprintf(f,
            "\" NumberType=\"%s\" Precision=\"%d\" Format=\"Binary\" Endian=\"%s\" "
            "Seek=\"%llu\">%s</DataItem>\n",
            type, prec, endian, (unsigned long long)at + row * k, ref);
    return 0;
}

/* The n doubles of the 1-D dataset path (a time axis), malloc'd; NULL on failure. */
static double *read_doubles(hid_t h, const char *path, hsize_t n)
{
    double *v = malloc((n ? n : 1) * sizeof *v);
    hid_t ds = H5Dopen2(h, path, H5P_DEFAULT);
    int ok = v && ds >= 0 && H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0;
    if (ds >= 0)
        H5Dclose(ds);
    if (!ok) {
        free(v);
        return NULL;
    }
    return v;
}

/* <Attribute> holding the dataset at path (k < 0) or its row k; ind is the
 * attribute's indentation.  Nothing when the dataset is absent. */
static void attribute(FILE *f, const char *ind, const char *name, const char *atype,
                      const char *center, hid_t h, const char *ref, const char *path, long long k)
{
    char inner[32];
    hsize_t d[3];
    if (dims_of(h, path, d) < 1)
        return;
    snprintf(inner, sizeof inner, "%s  ", ind);
    fprintf(f, "%s<Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"%s\">\n", ind, name, atype,
            center);
    if (k < 0)
        item(f, inner, h, ref, path);
    else
        row_item(f, inner, h, ref, path, (hsize_t)k);
    fprintf(f, "%s</Attribute>\n", ind);
}

/* A Polyvertex topology of n vertex cells whose connectivity is the id
 * dataset 0..n-1 (the Xdmf3 reader makes no cells without one), inline for
 * files without it. */
static void vertices(FILE *f, const char *ind, hid_t h, const char *ref, const char *id, size_t n)
{
    hsize_t d[3];
    char inner[32];
    snprintf(inner, sizeof inner, "%s  ", ind);
    fprintf(f,
            "%s<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
            "NodesPerElement=\"1\">\n",
            ind, n);
    if (dims_of(h, id, d) != 1 || d[0] != n || item(f, inner, h, ref, id) != 0) {
        fprintf(f,
                "%s<DataItem Dimensions=\"%zu\" NumberType=\"Int\" Precision=\"8\" Format=\"XML\">",
                inner, n);
        for (size_t i = 0; i < n; i++)
            fprintf(f, i % 16 == 15 ? "%zu\n" : "%zu ", i);
        fprintf(f, "</DataItem>\n");
    }
    fprintf(f, "%s</Topology>\n", ind);
}

/* The grains: one vertex cell per grain with radius, species and id. */
static void grains_grid(FILE *f, hid_t h, const char *ref, size_t n, int dim)
{
    fprintf(f, "    <Grid Name=\"grains\" GridType=\"Uniform\">\n");
    vertices(f, "      ", h, ref, "/particles/grains/id", n);
    fprintf(f, "      <Geometry GeometryType=\"%s\">\n", dim == 3 ? "XYZ" : "XY");
    item(f, "        ", h, ref, "/particles/grains/position");
    fprintf(f, "      </Geometry>\n");
    attribute(f, "      ", "radius", "Scalar", "Node", h, ref, "/particles/grains/radius", -1);
    attribute(f, "      ", "species", "Scalar", "Node", h, ref, "/particles/grains/species", -1);
    attribute(f, "      ", "id", "Scalar", "Node", h, ref, "/particles/grains/id", -1);
    fprintf(f, "    </Grid>\n");
}

/* A tetfill result's mesh: nodes [n][3] as XYZ geometry, tets [m][4] (node
 * indices) as Tetrahedron topology (files before H5MD 1.1 layout hold them
 * flat, [3n] and [4m]: read alike), the region of each tet as a cell
 * attribute. */
static void mesh_grid(FILE *f, hid_t h, const char *ref)
{
    const char *nodes = "/observables/tetfill/mesh_nodes", *tets = "/observables/tetfill/mesh_tets",
               *regions = "/observables/tetfill/mesh_regions";
    hsize_t dn[3], dt[3], dr[3];
    int rn = dims_of(h, nodes, dn), rt = dims_of(h, tets, dt);
    unsigned long long nn = rn == 2 && dn[1] == 3 ? dn[0]
        : rn == 1 && dn[0] % 3 == 0               ? dn[0] / 3
                                                  : 0,
                       nt = rt == 2 && dt[1] == 4 ? dt[0]
        : rt == 1 && dt[0] % 4 == 0               ? dt[0] / 4
                                                  : 0;
    if (!nn || !nt)
        return;
    fprintf(f,
            "    <Grid Name=\"mesh\" GridType=\"Uniform\">\n"
            "      <Topology TopologyType=\"Tetrahedron\" NumberOfElements=\"%llu\" "
            "NodesPerElement=\"4\">\n",
            nt);
    item(f, "        ", h, ref, tets);
    fprintf(f, "      </Topology>\n      <Geometry GeometryType=\"XYZ\">\n");
    item(f, "        ", h, ref, nodes);
    fprintf(f, "      </Geometry>\n");
    if (dims_of(h, regions, dr) == 1 && dr[0] == nt)
        attribute(f, "      ", "region", "Scalar", "Cell", h, ref, regions, -1);
    fprintf(f, "    </Grid>\n");
}

/* A homogenize result's load path: a temporal collection with one grid per
 * recorded step from /particles/rve (deformed centres: row k of
 * position/value; radius, species, id; the contact force per grain: row k
 * of contact_force/value). */
static int steps_grid(FILE *f, hid_t h, const char *ref)
{
    const char *pos = "/particles/rve/position/value", *frc = "/particles/rve/contact_force/value",
               *tim = "/particles/rve/position/time";
    hsize_t dx[3], df[3], dt[3], dd[3];
    if (dims_of(h, pos, dx) != 3 || dims_of(h, tim, dt) != 1 || dt[0] != dx[0] || !dx[0] ||
        (dx[2] != 2 && dx[2] != 3) || dims_of(h, "/particles/rve/id", dd) != 1 || dd[0] != dx[1])
        return 0;
    /* the rows are read by their offset: a dataset without one is no load path here */
    int readable = has_offset(h, pos);
    double *t = readable ? read_doubles(h, tim, dt[0]) : NULL;
    if (!t)
        return 0;
    int with_force = dims_of(h, frc, df) == 2 && df[0] == dx[0] && df[1] == dx[1];
    const size_t n = (size_t)dx[1];
    fprintf(f,
            "    <Grid Name=\"load steps\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (hsize_t k = 0; k < dx[0]; k++) {
        fprintf(f,
                "      <Grid Name=\"step %llu\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%.17g\"/>\n",
                (unsigned long long)k, t[k]);
        vertices(f, "        ", h, ref, "/particles/rve/id", n);
        fprintf(f, "        <Geometry GeometryType=\"%s\">\n", dx[2] == 3 ? "XYZ" : "XY");
        row_item(f, "          ", h, ref, pos, k);
        fprintf(f, "        </Geometry>\n");
        attribute(f, "        ", "radius", "Scalar", "Node", h, ref, "/particles/rve/radius", -1);
        attribute(f, "        ", "species", "Scalar", "Node", h, ref, "/particles/rve/species", -1);
        attribute(f, "        ", "id", "Scalar", "Node", h, ref, "/particles/rve/id", -1);
        if (with_force)
            attribute(f, "        ", "contact_force", "Scalar", "Node", h, ref, frc, (long long)k);
        fprintf(f, "      </Grid>\n");
    }
    fprintf(f, "    </Grid>\n");
    free(t);
    return 1;
}

/* An fe2 result's macro mesh over its converged load steps: a temporal
 * collection of the deformed mesh (Quadrilateral, Triangle or Mixed from
 * /observables/fe2/mesh/xdmf_topology) with the displacement per node and
 * the element-averaged von Mises stress per cell: row k of each series'
 * value. */
static int fe2_grid(FILE *f, hid_t h, const char *ref)
{
    const char *top = "/observables/fe2/mesh/xdmf_topology", *el = "/observables/fe2/mesh/elements",
               *tim = "/observables/fe2/load_steps/time", *pos = "/observables/fe2/position/value";
    hsize_t dt[3], de[3], dk[3], dn[3];
    if (dims_of(h, top, dt) != 1 || dims_of(h, el, de) != 2 || dims_of(h, tim, dk) != 1 || !dk[0] ||
        dims_of(h, pos, dn) != 3 || dn[0] != dk[0])
        return 0;
    int readable = has_offset(h, pos);
    /* the flat topology's length tells the kind: 4 or 3 per element, else Mixed */
    const char *kind = dt[0] == 4 * de[0] ? "Quadrilateral"
        : dt[0] == 3 * de[0]              ? "Triangle"
                                          : "Mixed";
    double *t = readable ? read_doubles(h, tim, dk[0]) : NULL;
    if (!t)
        return 0;
    const unsigned long long ne = de[0];
    int npe = !strcmp(kind, "Triangle") ? 3 : !strcmp(kind, "Quadrilateral") ? 4 : 0;
    fprintf(f,
            "    <Grid Name=\"load steps\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
    for (hsize_t k = 0; k < dk[0]; k++) {
        fprintf(f,
                "      <Grid Name=\"step %llu\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%.17g\"/>\n",
                (unsigned long long)k, t[k]);
        if (npe)
            fprintf(f,
                    "        <Topology TopologyType=\"%s\" NumberOfElements=\"%llu\" "
                    "NodesPerElement=\"%d\">\n",
                    kind, ne, npe);
        else
            fprintf(f, "        <Topology TopologyType=\"Mixed\" NumberOfElements=\"%llu\">\n", ne);
        item(f, "          ", h, ref, top);
        fprintf(f, "        </Topology>\n        <Geometry GeometryType=\"XY\">\n");
        row_item(f, "          ", h, ref, pos, k);
        fprintf(f, "        </Geometry>\n");
        attribute(f, "        ", "displacement", "Vector", "Node", h, ref,
                  "/observables/fe2/displacement/value", (long long)k);
        attribute(f, "        ", "von_mises", "Scalar", "Cell", h, ref,
                  "/observables/fe2/von_mises_element/value", (long long)k);
        fprintf(f, "      </Grid>\n");
    }
    fprintf(f, "    </Grid>\n");
    free(t);
    return 1;
}

int pk_xdmf_write(const char *h5_path, const char *h5_ref, const char *xdmf_path, char *err,
                  size_t errlen)
{
    pk_box b;
    pk_particles p;
    if (pk_h5_read_particles(h5_path, &b, &p, err, errlen) != 0)
        return -1;
    size_t n = p.n;
    pk_particles_free(&p);
    char rel[PATH_MAX];
    if (!h5_ref) {
        if (pk_xdmf_relative_ref(h5_path, xdmf_path, rel, sizeof rel) != 0) {
            snprintf(err, errlen, "cannot resolve the folders of %s and %s", h5_path, xdmf_path);
            return -1;
        }
        h5_ref = rel;
    }
    hid_t h = H5Fopen(h5_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (h < 0) {
        snprintf(err, errlen, "cannot open %s", h5_path);
        return -1;
    }
    char ref[1024], tmp[1100];
    xml_escape(h5_ref, ref, sizeof ref);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", xdmf_path, (long)getpid());
    /* the mode of the result file it describes */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, PK_RESULT_FILE_MODE);
    FILE *f = fd < 0 ? NULL : fdopen(fd, "w");
    if (!f) {
        if (fd >= 0)
            close(fd);
        H5Fclose(h);
        snprintf(err, errlen, "cannot write %s", tmp);
        return -1;
    }
    fprintf(f,
            "<?xml version=\"1.0\" ?>\n"
            "<!-- packd result: open with ParaView's Xdmf3 reader; the data is in %s -->\n"
            "<Xdmf Version=\"3.0\">\n"
            "  <Domain>\n",
            ref);
    /* a load path replaces the reference grains: the Xdmf3 reader shows only
     * the temporal collection of a domain that has one */
    if (!fe2_grid(f, h, ref) && !steps_grid(f, h, ref))
        grains_grid(f, h, ref, n, b.dim);
    mesh_grid(f, h, ref);
    fprintf(f, "  </Domain>\n</Xdmf>\n");
    H5Fclose(h);
    if (fclose(f) != 0 || rename(tmp, xdmf_path) != 0) {
        unlink(tmp);
        snprintf(err, errlen, "cannot write %s", xdmf_path);
        return -1;
    }
    return 0;
}
