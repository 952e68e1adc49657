/* xdmf.c — the XDMF 3 sidecar of a result file (contract in xdmf.h). */
#include "xdmf.h"

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

/* 1 when the file has /particles/grains/id (older files do not). */
static int has_ids(const char *h5_path)
{
    hid_t f = H5Fopen(h5_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return 0;
    int yes = H5Lexists(f, "/particles", H5P_DEFAULT) > 0 &&
        H5Lexists(f, "/particles/grains", H5P_DEFAULT) > 0 &&
        H5Lexists(f, "/particles/grains/id", H5P_DEFAULT) > 0;
    H5Fclose(f);
    return yes;
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
    char ref[1024], tmp[1100];
    xml_escape(h5_ref, ref, sizeof ref);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", xdmf_path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        snprintf(err, errlen, "cannot write %s", tmp);
        return -1;
    }
    fprintf(f,
            "<?xml version=\"1.0\" ?>\n"
            "<!-- packd grains: open with ParaView's Xdmf3 reader; the data is in %s -->\n"
            "<Xdmf Version=\"3.0\">\n"
            "  <Domain>\n"
            "    <Grid Name=\"grains\" GridType=\"Uniform\">\n"
            "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
            "NodesPerElement=\"1\">\n",
            ref, n);
    /* the Xdmf3 reader makes no cells without the connectivity (0..N-1) */
    if (has_ids(h5_path)) {
        fprintf(f,
                "        <DataItem Dimensions=\"%zu 1\" NumberType=\"Int\" Precision=\"8\" "
                "Format=\"HDF\">%s:/particles/grains/id</DataItem>\n",
                n, ref);
    } else {
        fprintf(f,
                "        <DataItem Dimensions=\"%zu 1\" NumberType=\"Int\" Precision=\"8\" "
                "Format=\"XML\">",
                n);
        for (size_t i = 0; i < n; i++)
            fprintf(f, i % 16 == 15 ? "%zu\n" : "%zu ", i);
        fprintf(f, "</DataItem>\n");
    }
    fprintf(f,
            "      </Topology>\n"
            "      <Geometry GeometryType=\"%s\">\n"
            "        <DataItem Dimensions=\"%zu %d\" NumberType=\"Float\" Precision=\"8\" "
            "Format=\"HDF\">%s:/particles/grains/position</DataItem>\n"
            "      </Geometry>\n"
            "      <Attribute Name=\"radius\" AttributeType=\"Scalar\" Center=\"Node\">\n"
            "        <DataItem Dimensions=\"%zu\" NumberType=\"Float\" Precision=\"8\" "
            "Format=\"HDF\">%s:/particles/grains/radius</DataItem>\n"
            "      </Attribute>\n"
            "      <Attribute Name=\"species\" AttributeType=\"Scalar\" Center=\"Node\">\n"
            "        <DataItem Dimensions=\"%zu\" NumberType=\"Int\" Precision=\"4\" "
            "Format=\"HDF\">%s:/particles/grains/species</DataItem>\n"
            "      </Attribute>\n"
            "    </Grid>\n"
            "  </Domain>\n"
            "</Xdmf>\n",
            b.dim == 3 ? "XYZ" : "XY", n, b.dim, ref, n, ref, n, ref);
    if (fclose(f) != 0 || rename(tmp, xdmf_path) != 0) {
        unlink(tmp);
        snprintf(err, errlen, "cannot write %s", xdmf_path);
        return -1;
    }
    return 0;
}
