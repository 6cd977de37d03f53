// SPDX-License-Identifier: GPL-3.0-or-later
#include "stage_options.h"

#include <nlohmann/json.hpp>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"

namespace zomefab::cli {

Vec3d parsePrinterMm(const std::string& text) {
    Vec3d v{};
    char s1 = 0, s2 = 0, rest = 0;
    std::istringstream in(text);
    const auto isSeparator = [](char c) { return c == 'x' || c == 'X' || c == ','; };
    if (!(in >> v[0] >> s1 >> v[1] >> s2 >> v[2]) || !isSeparator(s1) || !isSeparator(s2) || (in >> rest) ||
        !(v[0] > 0 && v[1] > 0 && v[2] > 0))
        throw Error(ErrorCode::Usage,
                    "--printer-mm: expected three positive sizes in mm, e.g. 200x200x200, got \"" + text + "\"");
    return v;
}

partition::SalientSphere parseSalientSphere(const std::string& text) {
    partition::SalientSphere s;
    char c1 = 0, c2 = 0, c3 = 0, rest = 0;
    std::istringstream in(text);
    if (!(in >> s.centerMm[0] >> c1 >> s.centerMm[1] >> c2 >> s.centerMm[2] >> c3 >> s.radiusMm) || c1 != ',' ||
        c2 != ',' || c3 != ',' || (in >> rest) || !(s.radiusMm > 0))
        throw Error(ErrorCode::Usage, "--salient: expected x,y,z,r in mm with r > 0, got \"" + text + "\"");
    return s;
}

std::vector<uint32_t> readSalientFaceList(const std::string& path, size_t faceCount) {
    nlohmann::json j = nlohmann::json::parse(readInputBytes(path), nullptr, false);
    if (j.is_discarded()) throw Error(ErrorCode::InvalidInput, "invalid JSON", path);
    if (j.is_object() && j.contains("salient_faces")) j = j["salient_faces"];
    if (!j.is_array())
        throw Error(ErrorCode::InvalidInput, "expected a list of face indices or {\"salient_faces\": [...]}", path);
    std::vector<uint32_t> faces;
    for (const nlohmann::json& v : j) {
        if (!v.is_number_unsigned() || v.get<uint64_t>() >= faceCount)
            throw Error(ErrorCode::InvalidInput,
                        "salient face " + v.dump() + " is not a face index below " + std::to_string(faceCount), path);
        faces.push_back(v.get<uint32_t>());
    }
    return faces;
}

}  // namespace zomefab::cli
