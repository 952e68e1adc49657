#include "xdmf.h"

#include <stdio.h>
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

int pk_xdmf_write(const char *h5_path, const char *h5_ref, const char *xdmf_path, char *err,
                  size_t errlen)
{
    pk_box b;
    pk_particles p;
    if (pk_h5_read_particles(h5_path, &b, &p, err, errlen) != 0)
        return -1;
    size_t n = p.n;
    pk_particles_free(&p);
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
            "      <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" NodesPerElement=\"1\"/>\n"
            "      <Geometry GeometryType=\"%s\">\n"
            "        <DataItem Dimensions=\"%zu %d\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/particles/grains/position</DataItem>\n"
            "      </Geometry>\n"
            "      <Attribute Name=\"radius\" AttributeType=\"Scalar\" Center=\"Node\">\n"
            "        <DataItem Dimensions=\"%zu\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">%s:/particles/grains/radius</DataItem>\n"
            "      </Attribute>\n"
            "      <Attribute Name=\"species\" AttributeType=\"Scalar\" Center=\"Node\">\n"
            "        <DataItem Dimensions=\"%zu\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">%s:/particles/grains/species</DataItem>\n"
            "      </Attribute>\n"
            "    </Grid>\n"
            "  </Domain>\n"
            "</Xdmf>\n",
            ref, n, b.dim == 3 ? "XYZ" : "XY", n, b.dim, ref, n, ref, n, ref);
    if (fclose(f) != 0 || rename(tmp, xdmf_path) != 0) {
        unlink(tmp);
        snprintf(err, errlen, "cannot write %s", xdmf_path);
        return -1;
    }
    return 0;
}
