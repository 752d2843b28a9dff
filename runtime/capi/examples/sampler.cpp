// A pbrt-style sampler over a nuld blob, through the C ABI (nuld.h): made for one
// shading point, as a pbrt BSDF is, `Sample(u)` returns a direction and its pdf,
// `PDF(wi)` the pdf of any direction (for multiple importance sampling). Build and
// run it as the README says ("C and C++"): build the library,
//   cargo build -p nuld-capi --profile capi --no-default-features
// then compile this file against it and run it on a blob,
//   c++ -std=c++17 -O2 -Iruntime/capi/include runtime/capi/examples/sampler.cpp
//       target/capi/libnuld_capi.a -o target/capi/sampler && target/capi/sampler out/brdf/brdf.nuld
#include "nuld.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

struct Vector3f {
    float x, y, z;
};

// What pbrt's samplers return: a direction, its pdf and, for nuld, the estimator
// weight (the BRDF's albedo, or the map's irradiance) that every sample shares.
struct DirectionSample {
    Vector3f wi;
    float pdf;
    float weight;
};

// A blob's bytes, 16-byte aligned as nuld_blob_parse requires, and the NuldBlob
// that borrows them: keep both for as long as any sampler of the blob is used.
class NuldBlobFile {
  public:
    explicit NuldBlobFile(const char *path) {
        std::ifstream f(path, std::ios::binary | std::ios::ate);
        if (!f) throw std::runtime_error(std::string("cannot read ") + path);
        std::size_t len = static_cast<std::size_t>(f.tellg());
        bytes_.reset(static_cast<char *>(std::aligned_alloc(16, (len + 15) / 16 * 16)));
        f.seekg(0).read(bytes_.get(), static_cast<std::streamsize>(len));
        int32_t rc = nuld_blob_parse(reinterpret_cast<const uint8_t *>(bytes_.get()), len, &blob_);
        if (rc == NULD_OK) rc = nuld_blob_info(&blob_, &info_);
        if (rc != NULD_OK) throw std::runtime_error(std::string(path) + ": " + nuld_error_message(rc));
    }
    const NuldBlob *blob() const { return &blob_; }
    const NuldBlobInfo &info() const { return info_; }

  private:
    struct Free {
        void operator()(char *p) const { std::free(p); }
    };
    std::unique_ptr<char, Free> bytes_;
    NuldBlob blob_;
    NuldBlobInfo info_;
};

// The sampler of one shading point: a BRDF blob's view `wo` (local frame, z = the
// normal), roughness and metallic, or an environment blob's normal `n` (world
// frame). `pixel` picks the set and its random shift (any uint32_t, e.g. a hash of
// the pixel); `u` in Sample(u) is the index of the sample, 0 to N - 1.
class NuldSampler {
  public:
    NuldSampler(const NuldBlobFile &file, Vector3f wo_or_n, float roughness, float metallic,
                uint32_t pixel)
        : file_(file), at_(wo_or_n), roughness_(roughness), metallic_(metallic), pixel_(pixel) {}

    std::optional<DirectionSample> Sample(uint32_t u) const {
        const NuldVec3 at = {at_.x, at_.y, at_.z};
        NuldSample s;
        // The unbiased mode: every sample drawn exactly from its pdf.
        int32_t rc = Brdf() ? nuld_brdf_sample_randomized(file_.blob(), NULD_MODE_TABLE, at,
                                                          roughness_, metallic_, pixel_, u,
                                                          pixel_, &s)
                            : nuld_envmap_sample_randomized(file_.blob(), NULD_MODE_TABLE, at,
                                                            pixel_, u, pixel_, &s);
        if (rc != NULD_OK) return std::nullopt;
        return DirectionSample{{s.direction[0], s.direction[1], s.direction[2]}, s.pdf, s.weight};
    }

    // The pdf of a sample in direction wi.
    float PDF(Vector3f wi) const {
        const NuldVec3 at = {at_.x, at_.y, at_.z}, d = {wi.x, wi.y, wi.z};
        float pdf = 0;
        int32_t rc = Brdf() ? nuld_brdf_pdf(file_.blob(), at, roughness_, metallic_, d, &pdf)
                            : nuld_envmap_pdf(file_.blob(), at, d, &pdf);
        return rc == NULD_OK ? pdf : 0;
    }

    uint32_t Count() const { return file_.info().len; }
    bool Brdf() const { return file_.info().target == NULD_TARGET_GLTF_BRDF; }

  private:
    const NuldBlobFile &file_;
    Vector3f at_;
    float roughness_;
    float metallic_;
    uint32_t pixel_;
};

int main(int argc, char **argv) try {
    if (argc != 2) throw std::runtime_error("usage: sampler FILE.nuld");
    NuldBlobFile file(argv[1]);
    if (file.info().kind != NULD_KIND_CONDITIONAL)
        throw std::runtime_error("a point set: sample it with nuld_point_2d or nuld_direction");
    bool brdf = file.info().target == NULD_TARGET_GLTF_BRDF;
    Vector3f at = brdf ? Vector3f{0.5f, 0.2f, 0.8f} : Vector3f{0.3f, -0.2f, 0.9f};
    NuldSampler sampler(file, at, 0.3f, 1.0f, 17);  // a metal for a BRDF blob
    // For a BRDF blob, light reflected from a sky of radiance 1 + max(0, x); for an
    // environment blob, the unbiased estimate of the cosine's integral, pi.
    double estimate = 0, worst_pdf_error = 0;
    for (uint32_t u = 0; u < sampler.Count(); u++) {
        std::optional<DirectionSample> s = sampler.Sample(u);
        if (!s) throw std::runtime_error(nuld_error_message(nuld_last_error()));
        if (u < 3)
            std::printf("Sample(%u): wi (%.5f, %.5f, %.5f), pdf %.5f, weight %.5f\n", u, s->wi.x,
                        s->wi.y, s->wi.z, s->pdf, s->weight);
        if (brdf) {
            estimate += s->weight * (1 + std::fmax(0.0f, s->wi.x)) / sampler.Count();
        } else {
            float cos = at.x * s->wi.x + at.y * s->wi.y + at.z * s->wi.z;
            float norm = std::sqrt(at.x * at.x + at.y * at.y + at.z * at.z);
            estimate += std::fmax(0.0f, cos / norm) / s->pdf / sampler.Count();
        }
        if (s->pdf > 0)
            worst_pdf_error = std::fmax(worst_pdf_error, std::fabs(sampler.PDF(s->wi) / s->pdf - 1));
    }
    if (brdf)
        std::printf("metal BRDF, N = %u: reflected radiance %.5f; "
                    "PDF(wi) / Sample(u).pdf - 1 at most %.1e\n",
                    sampler.Count(), estimate, worst_pdf_error);
    else
        std::printf("environment, N = %u: integral of the cosine %.4f (pi = 3.1416); "
                    "PDF(wi) / Sample(u).pdf - 1 at most %.1e\n",
                    sampler.Count(), estimate, worst_pdf_error);
    return 0;
} catch (const std::exception &e) {
    std::fprintf(stderr, "sampler: %s\n", e.what());
    return 1;
}
