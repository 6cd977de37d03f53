// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/structure_json.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/version.h"

namespace zomefab::zome {

using nlohmann::json;

namespace {

[[noreturn]] void fail(const std::string& message) { throw Error(ErrorCode::InvalidInput, message); }

/// An integer JSON value (no floats, no strings), or an error "<what> must be an integer".
int64_t requireInt(const json& j, const std::string& what) {
    if (j.is_number_unsigned()) {
        const uint64_t u = j.get<uint64_t>();
        if (u > uint64_t(std::numeric_limits<int64_t>::max())) fail(what + " is out of range");
        return int64_t(u);
    }
    if (j.is_number_integer()) return j.get<int64_t>();
    fail(what + " must be an integer");
}

const json* member(const json& object, const char* key) {
    auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
}

std::string ballLabel(int64_t id) { return "ball " + std::to_string(id); }

std::string describe(const StrutMatch& m) {
    return std::string(colorName(m.color)) + " " + partName(m.color, m.size);
}

GoldenVector3 readExact(const json& j, const std::string& who) {
    if (!j.is_array() || j.size() != 3) fail(who + ": \"exact\" must be 3 pairs [a, b]");
    GoldenVector3 v;
    for (int i = 0; i < 3; ++i) {
        const json& pair = j[size_t(i)];
        if (!pair.is_array() || pair.size() != 2) fail(who + ": \"exact\" must be 3 pairs [a, b]");
        const int64_t a = requireInt(pair[0], who + ": exact coefficient");
        const int64_t b = requireInt(pair[1], who + ": exact coefficient");
        if (a > kMaxExactCoefficient || a < -kMaxExactCoefficient || b > kMaxExactCoefficient ||
            b < -kMaxExactCoefficient)
            fail(who + ": exact coefficient out of range (|a|, |b| <= 2^40)");
        v[i] = Golden{a, b};
    }
    return v;
}

/// Reads strut @p i and adds it to @p s, checking what the file declares against the exact vector.
void addStrutFromJson(Structure& s, const json& st, size_t i) {
    const std::string where = "strut " + std::to_string(i);
    if (!st.is_object()) fail(where + " is not an object");
    const json* ja = member(st, "a");
    const json* jb = member(st, "b");
    if (!ja || !jb) fail(where + ": needs ball ids \"a\" and \"b\"");
    const int64_t a = requireInt(*ja, where + ": a");
    const int64_t b = requireInt(*jb, where + ": b");
    for (int64_t end : {a, b})
        if (end < 0 || end >= int64_t(s.ballIdBound()) || !s.hasBall(BallId(end)))
            fail(where + ": unknown ball id " + std::to_string(end));
    const std::string who = where + " (" + ballLabel(a) + " to " + ballLabel(b) + ")";
    if (a == b) fail(who + ": both ends are the same ball");
    const GoldenVector3 v = s.ball(BallId(b)).position - s.ball(BallId(a)).position;
    const std::optional<StrutMatch> m = matchStrut(v);
    if (!m) {
        std::string why = "vector " + v.toString() + " is not a Zome strut";
        if (const std::optional<int> h = parallelHole(v))
            why += " (parallel to hole " + std::to_string(*h) + " but not a " + colorName(holeColor(*h)) +
                   " catalogue length)";
        fail(who + ": " + why);
    }
    if (const json* c = member(st, "color")) {
        if (!c->is_string() || !colorFromName(c->get<std::string>()))
            fail(who + ": color must be \"blue\", \"yellow\" or \"red\"");
        if (*colorFromName(c->get<std::string>()) != m->color)
            fail(who + ": color is " + c->get<std::string>() + " but the vector is a " + describe(*m) +
                 " strut");
    }
    if (const json* z = member(st, "size")) {
        const int64_t size = requireInt(*z, who + ": size");
        if (size != m->size)
            fail(who + ": size is " + std::to_string(size) + " but the vector is a " + describe(*m) +
                 " strut");
    }
    if (const json* h = member(st, "hole_a")) {
        const int64_t hole = requireInt(*h, who + ": hole_a");
        if (hole != m->hole)
            fail(who + ": hole_a is " + std::to_string(hole) + " but the vector leaves " + ballLabel(a) +
                 " through hole " + std::to_string(m->hole));
    }
    if (const json* h = member(st, "hole_b")) {
        const int64_t hole = requireInt(*h, who + ": hole_b");
        if (hole != oppositeHole(m->hole))
            fail(who + ": hole_b is " + std::to_string(hole) + " but the vector enters " + ballLabel(b) +
                 " through hole " + std::to_string(oppositeHole(m->hole)));
    }
    for (const auto& [ball, hole] : {std::pair<int64_t, int>{a, m->hole}, {b, oppositeHole(m->hole)}}) {
        const StrutId used = s.ball(BallId(ball)).holes[size_t(hole)];
        if (used != kNoId)
            fail(who + ": hole " + std::to_string(hole) + " of " + ballLabel(ball) +
                 " is already used by strut " + std::to_string(used));
    }
    s.addStrut(BallId(a), m->hole, m->size);
}

}  // namespace

json structureToJson(const Structure& s, const Transform4d& transformMm) {
    json out = json::object();
    out["format"] = kStructureFormatName;
    out["version"] = kStructureFormatVersion;
    out["generator"] = generatorString();
    out["b0_mm"] = s.scale().b0Mm;
    out["unit_mm"] = s.scale().unitMm();
    // Exactly, so a reader places every ball at the same millimetres, bit for bit.
    out["origin_mm"] = toJson(s.scale().originMm);
    out["transform_mm"] = toJson(transformMm);
    json balls = json::array();
    for (BallId id : s.ballIds()) {
        const Ball& b = s.ball(id);
        json exact = json::array();
        for (int i = 0; i < 3; ++i) exact.push_back({b.position[i].a, b.position[i].b});
        balls.push_back({{"id", id},
                         {"exact", std::move(exact)},
                         {"mm", {b.positionMm[0], b.positionMm[1], b.positionMm[2]}}});
    }
    out["balls"] = std::move(balls);
    json struts = json::array();
    for (StrutId id : s.strutIds()) {
        const Strut& st = s.strut(id);
        struts.push_back({{"a", st.a},
                          {"b", st.b},
                          {"color", colorName(st.color)},
                          {"size", int(st.size)},
                          {"hole_a", int(st.holeA)},
                          {"hole_b", int(st.holeB)}});
    }
    out["struts"] = std::move(struts);
    return out;
}

Structure structureFromJson(const json& j, const ZomeScale& physical, const CollisionOptions& collision,
                            Transform4d* transformMm) {
    if (!j.is_object()) fail("not a zomefab.structure file: the top level is not a JSON object");
    const json* format = member(j, "format");
    if (!format) fail("not a zomefab.structure file: no \"format\"");
    if (!format->is_string() || format->get<std::string>() != kStructureFormatName)
        fail("not a zomefab.structure file: format is " + format->dump());
    const json* version = member(j, "version");
    if (!version) fail("no \"version\"");
    const int64_t major = requireInt(*version, "version");
    if (major != kStructureFormatVersion)
        fail("unsupported version " + std::to_string(major) + " (this build reads version " +
             std::to_string(kStructureFormatVersion) + ")");

    // Scale: b0_mm defines the unit; unit_mm is redundant and only checked (or used alone).
    ZomeScale scale = physical;
    scale.originMm = {0.0, 0.0, 0.0};
    const json* b0 = member(j, "b0_mm");
    const json* unit = member(j, "unit_mm");
    if (b0) {
        scale.b0Mm = numberFromJson(*b0, "b0_mm");
        if (scale.b0Mm <= 0.0) fail("b0_mm must be positive");
    }
    if (unit) {
        const double u = numberFromJson(*unit, "unit_mm");
        if (u <= 0.0) fail("unit_mm must be positive");
        if (!b0) {
            scale.b0Mm = u * 2.0 * kPhi * kPhi;
        } else if (std::abs(u - scale.unitMm()) > 1e-4 * scale.unitMm()) {
            std::ostringstream msg;
            msg.precision(8);
            msg << "unit_mm " << u << " contradicts b0_mm " << scale.b0Mm
                << " (expected b0_mm/(2 phi^2) = " << scale.unitMm() << ")";
            fail(msg.str());
        }
    }
    if (transformMm) *transformMm = Transform4d::identity();
    if (const json* t = member(j, "transform_mm")) {
        const Transform4d transform = transformFromJson(*t, "transform_mm");
        if (transformMm) *transformMm = transform;
    }

    const json* balls = member(j, "balls");
    const json* struts = member(j, "struts");
    if (!balls || !balls->is_array()) fail("\"balls\" must be an array");
    if (!struts || !struts->is_array()) fail("\"struts\" must be an array");

    // First pass over the balls: ids, exact positions, and the mm origin from the first `mm`.
    struct Entry {
        int64_t id;
        GoldenVector3 exact;
        const json* mm;
    };
    std::vector<Entry> entries;
    entries.reserve(balls->size());
    const int64_t maxId = 2 * int64_t(balls->size()) + 1024;
    for (size_t i = 0; i < balls->size(); ++i) {
        const json& b = (*balls)[i];
        const std::string where = "balls[" + std::to_string(i) + "]";
        if (!b.is_object()) fail(where + " is not an object");
        const json* id = member(b, "id");
        if (!id) fail(where + ": no \"id\"");
        const int64_t value = requireInt(*id, where + ": id");
        if (value < 0) fail(where + ": id must be non-negative");
        if (value >= maxId)
            fail(ballLabel(value) + ": id too large for " + std::to_string(balls->size()) +
                 " balls (ids must be below 2 x count + 1024)");
        const json* exact = member(b, "exact");
        if (!exact) fail(ballLabel(value) + ": no \"exact\" position");
        entries.push_back({value, readExact(*exact, ballLabel(value)), member(b, "mm")});
    }
    const json* origin = member(j, "origin_mm");
    if (origin) scale.originMm = vec3FromJson(*origin, "origin_mm");
    for (const Entry& e : entries) {
        if (!e.mm || origin) continue;
        const Vec3d mm = vec3FromJson(*e.mm, ballLabel(e.id) + ": mm");
        const Vec3d p = e.exact.toDouble();
        const double u = scale.unitMm();
        scale.originMm = {mm[0] - p[0] * u, mm[1] - p[1] * u, mm[2] - p[2] * u};
        break;
    }

    Structure s(scale, collision);
    for (const Entry& e : entries) {
        BallId id;
        try {
            id = s.addBallWithId(BallId(e.id), e.exact);
        } catch (const Error& err) {
            fail(err.message());  // already names the ball
        }
        if (e.mm) {
            const Vec3d mm = vec3FromJson(*e.mm, ballLabel(e.id) + ": mm");
            const Vec3d& expected = s.ball(id).positionMm;
            for (int k = 0; k < 3; ++k) {
                if (std::abs(mm[size_t(k)] - expected[size_t(k)]) > kMmCheckToleranceMm) {
                    std::ostringstream msg;
                    msg.precision(10);
                    msg << ballLabel(e.id) << ": mm [" << mm[0] << ", " << mm[1] << ", " << mm[2]
                        << "] does not match exact x unit_mm + origin [" << expected[0] << ", " << expected[1]
                        << ", " << expected[2] << "]";
                    fail(msg.str());
                }
            }
        }
    }

    for (size_t i = 0; i < struts->size(); ++i) addStrutFromJson(s, (*struts)[i], i);
    return s;
}

Structure structureFromJsonText(const std::string& text, const ZomeScale& physical,
                                const CollisionOptions& collision, Transform4d* transformMm) {
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        // nlohmann's message: "[json.exception.parse_error.101] parse error at line 1, column 5: ..."
        // (also out_of_range.406 for a number beyond double, found by fuzz_frame)
        std::string what = e.what();
        const size_t pos = what.find("] ");
        fail("invalid JSON: " + (pos == std::string::npos ? what : what.substr(pos + 2)));
    }
    return structureFromJson(j, physical, collision, transformMm);
}

std::string structureToVef(const Structure& s) {
    // Layout of vZome's VefVectorExporter.finishExport (version 6, explicit balls section),
    // reproduced line for line so vZome reads it like its own export.
    const std::vector<BallId> ids = s.ballIds();
    std::vector<uint32_t> vertexOf(s.ballIdBound(), 0);
    for (size_t i = 0; i < ids.size(); ++i) vertexOf[ids[i]] = uint32_t(i);
    auto number = [](const Golden& g) {
        return "(" + std::to_string(g.b) + "," + std::to_string(g.a) + ")";  // VEF: (phis,ones)
    };
    std::string out;
    out.reserve(ids.size() * 48 + s.strutCount() * 12 + 256);
    out += "vZome VEF 6 field golden\n";
    out += "\n" + std::to_string(ids.size()) + "\n";
    for (BallId id : ids) {
        const GoldenVector3& p = s.ball(id).position;
        out += "(0,0) " + number(p[0]) + " " + number(p[1]) + " " + number(p[2]) + "\n";
    }
    out += "\n\n";
    const std::vector<StrutId> struts = s.strutIds();
    out += "\n" + std::to_string(struts.size()) + "\n";
    for (StrutId id : struts) {
        const Strut& st = s.strut(id);
        out += std::to_string(vertexOf[st.a]) + " " + std::to_string(vertexOf[st.b]) + "\n";
    }
    out += "\n\n";
    out += "\n0\n";  // no panels
    out += "\n\n";
    out += "\n" + std::to_string(ids.size()) + "\n";
    for (size_t i = 0; i < ids.size(); ++i) {
        out += std::to_string(i) + " ";
        if ((i + 1) % 10 == 0) out += "\n";
    }
    out += "\n\n";
    return out;
}

json collisionToJson(const Collision& c) {
    return {{"kind", collisionKindName(c.kind)},
            {"first", c.first},
            {"second", c.second},
            {"distance_mm", c.distanceMm},
            {"limit_mm", c.limitMm}};
}

std::string describeCollision(const Collision& c) {
    const bool strutFirst = c.kind != CollisionKind::BallBall;
    const bool strutSecond = c.kind == CollisionKind::StrutStrut;
    return std::string(strutFirst ? "strut " : "ball ") + std::to_string(c.first) + " and " +
           (strutSecond ? "strut " : "ball ") + std::to_string(c.second) + " (" + collisionKindName(c.kind) +
           ", " + formatNumbers("%.2f mm < %.2f mm", c.distanceMm, c.limitMm) + ")";
}

json checkReportJson(const Structure& frame, const std::string& file,
                     const std::vector<Collision>& collisions, const PriceOptions& prices) {
    const ZomeScale& scale = frame.scale();
    json out = {{"file", file},
                {"valid", true},
                {"balls", frame.ballCount()},
                {"struts", frame.strutCount()},
                {"collision_free", collisions.empty()},
                {"collision_count", collisions.size()},
                {"collisions", json::array()},
                {"parts", partsListToJson(partsList(frame), prices)},
                {"scale",
                 {{"b0_mm", scale.b0Mm},
                  {"unit_mm", scale.unitMm()},
                  {"ball_diameter_mm", scale.ballDiameterMm},
                  {"blue_radius_mm", scale.blueRadiusMm},
                  {"yellow_radius_mm", scale.yellowRadiusMm},
                  {"red_radius_mm", scale.redRadiusMm},
                  {"clearance_mm", frame.collisionOptions().clearanceMm}}}};
    for (const Collision& c : collisions) out["collisions"].push_back(collisionToJson(c));
    return out;
}

}  // namespace zomefab::zome
