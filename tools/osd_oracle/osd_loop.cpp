// OpenSubdiv's Loop scheme behind a small C ABI, for tests and benches (the subdivision oracle).
//
// Built by tools/setup.sh against Debian's libosd-dev (OpenSubdiv 3.5) into out/osd/libosd_loop.so and
// loaded with ctypes by tools/osd_oracle/osd_oracle.py. Not shipped with the extension.
//
// One call refines a triangle mesh uniformly (Far::TopologyRefiner, Sdc::SCHEME_LOOP) and interpolates
// vertex data (V, D) and, optionally, one face-varying channel (N, W) in double precision
// (Far::PrimvarRefinerReal<double>). The handle keeps the refiner and the results until osd_loop_free.

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <chrono>
#include <cstring>
#include <vector>

using namespace OpenSubdiv;

namespace {

struct Row {  // one primvar row of `width` doubles inside a flat buffer
    double *p;
    int width;
    void Clear() { std::memset(p, 0, sizeof(double) * width); }
    void AddWithWeight(Row const &src, double w) {
        for (int i = 0; i < width; ++i) p[i] += w * src.p[i];
    }
};

struct Rows {  // indexable view of a flat buffer as rows
    double *base;
    int width;
    std::vector<Row> rows;
    Rows(double *b, int n, int w) : base(b), width(w), rows(n) {
        for (int i = 0; i < n; ++i) rows[i] = Row{b + (size_t)i * w, w};
    }
    Row &operator[](int i) { return rows[i]; }
    Row const &operator[](int i) const { return rows[i]; }
};

struct Result {
    Far::TopologyRefiner *refiner = nullptr;
    std::vector<double> values, fvar;  // last level
    int level = 0, width = 0, fvar_width = 0;
    double seconds_topology = 0.0, seconds_primvar = 0.0;
};

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Refine `values` (n_in rows of `width`) through levels 1..level with `interp(level, src, dst)`.
template <class F>
std::vector<double> refine_rows(Far::TopologyRefiner const &r, int level, int width, double const *values,
                                int n_in, F interp, bool fvar) {
    std::vector<double> src(values, values + (size_t)n_in * width);
    for (int l = 1; l <= level; ++l) {
        int n = fvar ? r.GetLevel(l).GetNumFVarValues(0) : r.GetLevel(l).GetNumVertices();
        std::vector<double> dst((size_t)n * width, 0.0);
        Rows s(src.data(), (int)(src.size() / width), width), d(dst.data(), n, width);
        interp(l, s, d);
        src.swap(dst);
    }
    return src;
}

}  // namespace

extern "C" {

// boundary: 1 = VTX_BOUNDARY_EDGE_ONLY, 2 = VTX_BOUNDARY_EDGE_AND_CORNER.
// fvar_interp: Sdc::Options::FVarLinearInterpolation (0 NONE .. 4 BOUNDARIES, 5 ALL).
// creases: n_creases vertex pairs with OpenSubdiv sharpness (10 = infinitely sharp); corners: vertex sharpness.
void *osd_loop_refine(int n_verts, int n_faces, int const *tris, int width, double const *values, int n_creases,
                      int const *crease_pairs, float const *crease_sharpness, int n_corners,
                      int const *corner_verts, float const *corner_sharpness, int boundary, int level,
                      int fvar_width, int n_fvar, int const *fvar_indices, double const *fvar_values,
                      int fvar_interp) {
    auto *res = new Result();
    double t0 = now();
    std::vector<int> sizes(n_faces, 3);
    Far::TopologyDescriptor desc;
    desc.numVertices = n_verts;
    desc.numFaces = n_faces;
    desc.numVertsPerFace = sizes.data();
    desc.vertIndicesPerFace = tris;
    desc.numCreases = n_creases;
    desc.creaseVertexIndexPairs = crease_pairs;
    desc.creaseWeights = crease_sharpness;
    desc.numCorners = n_corners;
    desc.cornerVertexIndices = corner_verts;
    desc.cornerWeights = corner_sharpness;
    Far::TopologyDescriptor::FVarChannel channel;
    if (fvar_width > 0) {
        channel.numValues = n_fvar;
        channel.valueIndices = fvar_indices;
        desc.numFVarChannels = 1;
        desc.fvarChannels = &channel;
    }
    Sdc::Options options;
    options.SetVtxBoundaryInterpolation(boundary == 2 ? Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER
                                                      : Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    options.SetFVarLinearInterpolation((Sdc::Options::FVarLinearInterpolation)fvar_interp);
    typedef Far::TopologyRefinerFactory<Far::TopologyDescriptor> Factory;
    res->refiner = Factory::Create(desc, Factory::Options(Sdc::SCHEME_LOOP, options));
    if (!res->refiner) {
        delete res;
        return nullptr;
    }
    Far::TopologyRefiner::UniformOptions uniform(level);
    uniform.fullTopologyInLastLevel = false;
    res->refiner->RefineUniform(uniform);
    double t1 = now();
    Far::PrimvarRefinerReal<double> primvar(*res->refiner);
    res->values = refine_rows(
        *res->refiner, level, width, values, n_verts,
        [&](int l, Rows const &s, Rows &d) { primvar.Interpolate(l, s, d); }, false);
    res->seconds_primvar = now() - t1;
    res->seconds_topology = t1 - t0;
    if (fvar_width > 0) {
        res->fvar = refine_rows(
            *res->refiner, level, fvar_width, fvar_values, n_fvar,
            [&](int l, Rows const &s, Rows &d) { primvar.InterpolateFaceVarying(l, s, d, 0); }, true);
    }
    res->level = level;
    res->width = width;
    res->fvar_width = fvar_width;
    return res;
}

// Sizes of the last level: vertices, faces, face-varying values; and the two timings (seconds).
void osd_loop_sizes(void *handle, int *n_verts, int *n_faces, int *n_fvar, double *seconds) {
    auto *res = static_cast<Result *>(handle);
    Far::TopologyLevel const &last = res->refiner->GetLevel(res->level);
    *n_verts = last.GetNumVertices();
    *n_faces = last.GetNumFaces();
    *n_fvar = res->fvar_width > 0 ? last.GetNumFVarValues(0) : 0;
    seconds[0] = res->seconds_topology;
    seconds[1] = res->seconds_primvar;
}

// Copy the last level out: values (V, width), triangles (F, 3), fvar values (N, fvar_width), fvar triangles (F, 3).
void osd_loop_fetch(void *handle, double *values, int *tris, double *fvar, int *fvar_tris) {
    auto *res = static_cast<Result *>(handle);
    Far::TopologyLevel const &last = res->refiner->GetLevel(res->level);
    std::memcpy(values, res->values.data(), sizeof(double) * res->values.size());
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        Far::ConstIndexArray fv = last.GetFaceVertices(f);
        for (int k = 0; k < 3; ++k) tris[3 * f + k] = fv[k];
        if (res->fvar_width > 0) {
            Far::ConstIndexArray ff = last.GetFaceFVarValues(f, 0);
            for (int k = 0; k < 3; ++k) fvar_tris[3 * f + k] = ff[k];
        }
    }
    if (res->fvar_width > 0) std::memcpy(fvar, res->fvar.data(), sizeof(double) * res->fvar.size());
}

void osd_loop_free(void *handle) {
    auto *res = static_cast<Result *>(handle);
    delete res->refiner;
    delete res;
}

}  // extern "C"
