// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Test helpers for GLB outputs: the container parsed back (JSON and binary chunk), a
/// bufferView's bytes, external commands, the Khronos glTF-Validator (through node) and
/// draco_decoder. Header-only; a test using khronosValidate() defines ZOMEFAB_NODE_DIR and
/// ZOMEFAB_VALIDATOR_SCRIPT (see tests/io/CMakeLists.txt).
#pragma once

#include <doctest/doctest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.h"

namespace zomefab::test {

/// A parsed GLB: its JSON and its binary chunk.
struct Glb {
    nlohmann::json json;
    std::string bin;
};

/// Parses the GLB container, checking its header and chunk alignment.
inline Glb parseGlb(const std::string& bytes) {
    Glb g;
    REQUIRE(bytes.size() >= 20);
    REQUIRE(bytes.compare(0, 4, "glTF") == 0);
    uint32_t version = 0, length = 0, jsonLength = 0;
    std::memcpy(&version, bytes.data() + 4, 4);
    std::memcpy(&length, bytes.data() + 8, 4);
    std::memcpy(&jsonLength, bytes.data() + 12, 4);
    CHECK(version == 2);
    CHECK(length == bytes.size());
    CHECK(jsonLength % 4 == 0);
    REQUIRE(bytes.compare(16, 4, "JSON") == 0);
    g.json = nlohmann::json::parse(bytes.substr(20, jsonLength));
    const size_t binHeader = 20 + jsonLength;
    if (binHeader < bytes.size()) {
        uint32_t binLength = 0;
        std::memcpy(&binLength, bytes.data() + binHeader, 4);
        CHECK(bytes.compare(binHeader + 4, 4, std::string("BIN\0", 4)) == 0);
        CHECK(binLength % 4 == 0);
        g.bin = bytes.substr(binHeader + 8, binLength);
        CHECK(binHeader + 8 + binLength == bytes.size());
    }
    return g;
}

/// The bytes of bufferView @p view of the binary chunk.
inline std::string viewBytes(const Glb& g, int view) {
    const nlohmann::json& v = g.json["bufferViews"][size_t(view)];
    CHECK(v["byteOffset"].get<size_t>() % 4 == 0);
    return g.bin.substr(v["byteOffset"].get<size_t>(), v["byteLength"].get<size_t>());
}

#if defined(ZOMEFAB_NODE_DIR) && defined(ZOMEFAB_VALIDATOR_SCRIPT)
/// The npm prefix holding gltf-validator (`make test-deps`); ZOMEFAB_NODE_DIR in the environment wins.
inline std::string nodePrefix() {
    const char* env = std::getenv("ZOMEFAB_NODE_DIR");
    return env ? env : ZOMEFAB_NODE_DIR;
}

/// Runs the Khronos validator on @p path; returns its JSON summary (errors, warnings, messages).
inline nlohmann::json khronosValidate(const std::string& path) {
    std::string out;
    const int code = runCapture(
        "node '" + std::string(ZOMEFAB_VALIDATOR_SCRIPT) + "' '" + nodePrefix() + "' '" + path + "' 2>&1",
        &out);
    INFO("validator output: " << out);
    REQUIRE(code >= 0);
    REQUIRE(code != 2);  // 2 = validator missing: run `make test-deps`
    return nlohmann::json::parse(out);
}
#endif

/// Decodes a Draco bitstream file with draco_decoder into @p objPath; returns the vertex and face
/// counts of the OBJ it wrote ({0, 0} when the decoder failed).
inline std::pair<size_t, size_t> dracoDecodeCounts(const std::string& drcPath, const std::string& objPath) {
    const std::string cmd = "draco_decoder -i '" + drcPath + "' -o '" + objPath + "' > /dev/null 2>&1";
    if (std::system(cmd.c_str()) != 0) return {0, 0};
    std::ifstream obj(objPath);
    std::string line;
    size_t vertices = 0, faces = 0;
    while (std::getline(obj, line)) {
        if (line.rfind("v ", 0) == 0) ++vertices;
        if (line.rfind("f ", 0) == 0) ++faces;
    }
    return {vertices, faces};
}

}  // namespace zomefab::test
