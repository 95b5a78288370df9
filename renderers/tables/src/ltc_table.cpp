#include "tyndall/tables/ltc_table.h"

#include "table_file.h"

#include "tyndall/core/error.h"
#include "tyndall/tables/ltsd_table.h"

#include <cmath>
#include <cstring>

namespace tyndall {

namespace {

using table_file::get;
using table_file::hex64;
using table_file::kChecksumOffset;
using table_file::put;

constexpr double kPi = 3.14159265358979323846;
constexpr char kMagic[8] = {'T', 'Y', 'L', 'T', 'C', '\r', '\n', '\0'};
constexpr std::size_t kHeaderBytes = 64;
constexpr std::size_t kEntryBytes = sizeof(shader::LtcEntry);
static_assert(kEntryBytes == 48, "LtcEntry must match its std430 layout (docs/tables.md)");

// Smith's Lambda for GGX, 0.5 (sqrt(1 + t) - 1) with t = tan^2 theta times the projected roughness squared, written
// without the cancellation at small t.
double ggxLambda(const glm::dvec3& w, double ax, double ay) {
    const double t = (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z);
    return 0.5 * t / (1.0 + std::sqrt(1.0 + t));
}

std::size_t entryCount(const std::array<int, 4>& sizes) {
    return std::size_t(sizes[0]) * std::size_t(sizes[1]) * std::size_t(sizes[2]) * std::size_t(sizes[3]);
}

}  // namespace

double ggxCosineLobe(const glm::dvec3& wo, const glm::dvec3& wi, double ax, double ay) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
    const glm::dvec3 h = glm::normalize(wo + wi);
    const double x = h.x / ax, y = h.y / ay;
    const double s = x * x + y * y + h.z * h.z;
    const double d = 1.0 / (kPi * ax * ay * s * s);
    const double g2 = 1.0 / (1.0 + ggxLambda(wo, ax, ay) + ggxLambda(wi, ax, ay));
    return d * g2 / (4.0 * wo.z);  // D G2 / (4 cos_o cos_i) times cos_i
}

double LtcTable::gridAlpha(int ia, int alphaCount, double alphaMin) {
    return alphaMin + (1.0 - alphaMin) * double(ia) / double(alphaCount - 1);
}

double LtcTable::gridCosTheta(int ix, int xCount) {
    const double x = double(ix) / double(xCount - 1);
    return std::max(1.0 - x * x, double(shader::kLtcMinCosTheta));
}

double LtcTable::gridTheta(int it, int thetaCount) {
    const double theta = 0.5 * kPi * double(it) / double(thetaCount - 1);
    return std::min(theta, std::acos(double(shader::kLtcMinCosTheta)));
}

double LtcTable::gridPhi(int ip, int phiCount) {
    return 0.5 * kPi * double(ip) / double(phiCount - 1);
}

double LtcTable::gridRatio(int ir, int ratioCount, double ratioMin) {
    return ratioMin + (1.0 - ratioMin) * double(ir) / double(ratioCount - 1);
}

shader::LtcEntry LtcTable::anisotropic(double alphaX, double alphaY, const glm::dvec3& wo,
                                       glm::mat3& toCanonical) const {
    TY_CHECK(dimensions == 4, "the anisotropic fetch needs the anisotropic table");
    const shader::LtcQuadrilinear q =
        shader::ltcFetchAnisotropic(float(alphaX), float(alphaY), glm::vec3(wo), thetaCount(), phiCount(), alphaCount(),
                                    ratioCount(), alphaMin, ratioMin);
    shader::LtcEntry e = shader::ltcZeroEntry();
    for (int k = 0; k < 16; ++k)
        e = shader::ltcAddWeighted(e, entries[size_t(shader::ltcCornerIndex(q, k))], shader::ltcCornerWeight(q, k));
    toCanonical = q.toCanonical;
    return e;
}

shader::LtcEntry LtcTable::isotropic(double alpha, double cosTheta) const {
    const shader::LtcBilinear f =
        shader::ltcFetchIsotropic(float(alpha), float(cosTheta), xCount(), alphaCount(), alphaMin);
    return shader::ltcBilinearBlend(entries[size_t(f.i00)], entries[size_t(f.i10)], entries[size_t(f.i01)],
                                    entries[size_t(f.i11)], f);
}

glm::dvec3 LtcTable::integral(const shader::SphericalPolygon& polygon, const glm::dvec3& wo, double alphaX,
                              double alphaY, const glm::dvec3& f0) const {
    if (wo.z <= 0.0) return glm::dvec3(0.0);
    if (isotropicTable()) {
        TY_CHECK(alphaX == alphaY, "the isotropic LTC table needs alphaX == alphaY");
        const shader::LtcEntry e = isotropic(alphaX, wo.z);
        const shader::SphericalPolygon local = shader::ltcToIsotropicFrame(polygon, glm::vec3(wo));
        return glm::dvec3(shader::ltcBrdfIntegral(e, glm::vec3(f0), local));
    }
    glm::mat3 toCanonical;
    const shader::LtcEntry e = anisotropic(alphaX, alphaY, wo, toCanonical);
    const glm::mat3 mInv = shader::ltsdInverse(shader::ltcMatrix(e)) * toCanonical;
    return glm::dvec3(shader::ltcFresnelNorm(e, glm::vec3(f0)) * shader::ltcPolygonIntegral(mInv, polygon));
}

// ---------------------------------------------------------------------------------------------------------------------
// File format (docs/tables.md, "LTC GGX tables")

void saveLtcTable(const LtcTable& table, const std::filesystem::path& file) {
    TY_CHECK(table.dimensions == 2 || table.dimensions == 4, "an LTC table has 2 or 4 dimensions");
    TY_CHECK(table.entries.size() == entryCount(table.sizes), "an LTC table holds the product of its sizes");
    std::vector<std::uint8_t> bytes(kHeaderBytes + kEntryBytes * table.entries.size(), 0);
    std::memcpy(bytes.data(), kMagic, sizeof kMagic);
    put<std::uint32_t>(bytes, 8, LtcTable::kVersion);
    put<std::uint32_t>(bytes, 12, std::uint32_t(table.dimensions));
    put<std::uint32_t>(bytes, 16, std::uint32_t(kEntryBytes));
    put<float>(bytes, 20, table.alphaMin);
    for (int d = 0; d < 4; ++d)
        put<std::uint32_t>(bytes, 24 + 4 * std::size_t(d), std::uint32_t(table.sizes[size_t(d)]));
    put<std::uint64_t>(bytes, 40, std::uint64_t(kEntryBytes * table.entries.size()));
    put<float>(bytes, 56, shader::kLtcMinCosTheta);
    put<float>(bytes, 60, table.ratioMin);
    std::memcpy(bytes.data() + kHeaderBytes, table.entries.data(), kEntryBytes * table.entries.size());
    const std::uint64_t checksum = ltsdTableChecksum(bytes);
    put<std::uint64_t>(bytes, kChecksumOffset, checksum);
    table_file::writeAtomically(file, bytes.data(), bytes.size());

    nlohmann::json sidecar = table.provenance.is_object() ? table.provenance : nlohmann::json::object();
    sidecar["table"] = file.filename().string();
    sidecar["checksum"] = hex64(checksum);
    const std::string text = sidecar.dump(2) + "\n";
    table_file::writeAtomically(file.string() + ".json", text.data(), text.size());
}

LtcTable loadLtcTable(const std::filesystem::path& file) {
    const auto fail = [&](const std::string& field, const std::string& message) {
        return InputError(InputLocation{file.string(), 0, 0, field}, message);
    };
    const std::vector<std::uint8_t> bytes = table_file::readAll(file, "LTC GGX table");
    if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        throw fail("header", "not an LTC table (no TYLTC magic, or shorter than its 64-byte header)");
    const auto version = get<std::uint32_t>(bytes, 8);
    if (version != LtcTable::kVersion)
        throw fail("header.version", "version " + std::to_string(version) + "; this Tyndall reads version " +
                                         std::to_string(LtcTable::kVersion) +
                                         " (re-fit with tyndall-fit-tables --ltc)");
    LtcTable table;
    table.path = file.string();
    table.dimensions = int(get<std::uint32_t>(bytes, 12));
    if (table.dimensions != 2 && table.dimensions != 4)
        throw fail("header.dimensions",
                   "must be 2 (isotropic) or 4 (anisotropic), got " + std::to_string(table.dimensions));
    const auto entryBytes = get<std::uint32_t>(bytes, 16);
    if (entryBytes != kEntryBytes) throw fail("header.entryBytes", "must be 48, got " + std::to_string(entryBytes));
    for (int d = 0; d < 4; ++d) {
        const auto n = get<std::uint32_t>(bytes, 24 + 4 * std::size_t(d));
        const bool used = d < table.dimensions;
        if (used ? (n < 2 || n > 4096) : n != 1)
            throw fail("header.sizes[" + std::to_string(d) + "]",
                       used ? "must be in [2, 4096], got " + std::to_string(n) : "must be 1, got " + std::to_string(n));
        table.sizes[size_t(d)] = int(n);
    }
    const std::uint64_t expectedPayload = std::uint64_t(entryCount(table.sizes)) * kEntryBytes;
    const auto payloadBytes = get<std::uint64_t>(bytes, 40);
    if (payloadBytes != expectedPayload || bytes.size() != kHeaderBytes + expectedPayload)
        throw fail("payload", "truncated or padded: " + std::to_string(bytes.size()) + " bytes, the header implies " +
                                  std::to_string(kHeaderBytes + expectedPayload));
    const auto stored = get<std::uint64_t>(bytes, kChecksumOffset);
    if (stored != ltsdTableChecksum(bytes))
        throw fail("header.checksum", "checksum mismatch: the file is corrupt (stored " + hex64(stored) +
                                          ", computed " + hex64(ltsdTableChecksum(bytes)) + ")");
    table.alphaMin = get<float>(bytes, 20);
    if (!(table.alphaMin > 0.0f && table.alphaMin < 1.0f))
        throw fail("header.alphaMin", "must be in (0, 1), got " + std::to_string(table.alphaMin));
    table.ratioMin = get<float>(bytes, 60);
    if (table.isotropicTable() ? table.ratioMin != 0.0f : !(table.ratioMin >= 0.0f && table.ratioMin < 1.0f))
        throw fail("header.ratioMin",
                   std::string(table.isotropicTable() ? "must be 0 in an isotropic table" : "must be in [0, 1)") +
                       ", got " + std::to_string(table.ratioMin));
    const float cosMin = get<float>(bytes, 56);
    if (cosMin != shader::kLtcMinCosTheta)
        throw fail("header.cosThetaMin", "must be " + std::to_string(shader::kLtcMinCosTheta) +
                                             " (the grazing clamp this Tyndall looks up with), got " +
                                             std::to_string(cosMin));
    table.entries.resize(entryCount(table.sizes));
    std::memcpy(table.entries.data(), bytes.data() + kHeaderBytes, payloadBytes);
    for (size_t i = 0; i < table.entries.size(); ++i) {
        const shader::LtcEntry& e = table.entries[i];
        const std::string field = "entries[" + std::to_string(i) + "]";
        for (float v : e.m)
            if (!std::isfinite(v)) throw fail(field + ".m", "a matrix element is not finite");
        const glm::mat3 m = shader::ltcMatrix(e);
        const double det = double(glm::determinant(m));
        const double scale = double(glm::length(m[0]) * glm::length(m[1]) * glm::length(m[2]));
        if (!(det > 1e-12 * scale) || !(scale > 0.0))
            throw fail(field + ".m", "the matrix is singular or flips orientation (det " + std::to_string(det) + ")");
        if (!(e.norm > 0.0f && e.norm <= 1.0f))
            throw fail(field + ".norm", "must be in (0, 1], got " + std::to_string(e.norm));
        if (!(e.fresnel >= 0.0f && e.fresnel <= e.norm))
            throw fail(field + ".fresnel", "must be in [0, norm], got " + std::to_string(e.fresnel));
        if (!(e.error >= 0.0f && e.error <= 2.0f))
            throw fail(field + ".error", "must be in [0, 2], got " + std::to_string(e.error));
    }

    const std::filesystem::path sidecar = file.string() + ".json";
    std::ifstream side(sidecar);
    if (side) {
        try {
            table.provenance = nlohmann::json::parse(side);
        } catch (const nlohmann::json::exception& e) {
            throw InputError(InputLocation{sidecar.string(), 0, 0, ""}, std::string("not valid JSON: ") + e.what());
        }
    }
    return table;
}

std::filesystem::path ltcTablePath(const std::string& name, const std::string& overrideDir) {
    return ltsdTablesDirectory(overrideDir) / (name + ".ltc");
}

}  // namespace tyndall
