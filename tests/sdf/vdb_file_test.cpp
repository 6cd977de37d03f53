// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/sdf/vdb_file.h"

#include <doctest/doctest.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/sdf/level_set_grid.h"

using namespace zomefab;
using namespace zomefab::sdf;

namespace {

ErrorCode parseCode(const std::string& bytes) {
    try {
        parseVdb(bytes, "in.vdb", RunContext::silent());
    } catch (const Error& e) {
        CHECK(std::string(e.what()).rfind("in.vdb: ", 0) == 0);  // names the file
        return e.code();
    }
    FAIL("no error");
    return ErrorCode::Internal;
}

/// A .vdb written by plain OpenVDB (no zomefab metadata).
std::string foreignVdb(openvdb::GridBase::Ptr grid) {
    openvdb::initialize();
    std::ostringstream out;
    openvdb::io::Stream(out).write({grid});
    return out.str();
}

}  // namespace

TEST_CASE("vdb_file: metadata and values survive a round trip, and bytes are deterministic") {
    LevelSet object = meshToLevelSet(test::makeSphere({0, 0, 10}, 12.0), {}, RunContext::silent());
    object.info().sourceFile = "some dir/bunny.stl";
    object.info().generator = "zomefab 9.9.9";
    object.info().transformMm = Transform4d::scaleTranslate(2.5, {1, -2, 3}) * Transform4d::yUpToZUp();
    object.info().interiorBandMm = 7.5;
    MeshToLevelSetOptions coarse;
    coarse.voxelMm = 2.0;
    coarse.interiorBandMm = std::numeric_limits<double>::infinity();
    coarse.name = "interior";
    const LevelSet interior =
        meshToLevelSet(test::makeSphere({0, 0, 10}, 12.0), coarse, RunContext::silent());

    const std::string bytes = serializeVdb({object, interior});
    CHECK(bytes == serializeVdb({object, interior}));  // no random UUID

    RunContext context;
    const std::vector<LevelSet> back = parseVdb(bytes, "x.vdb", context);
    CHECK(context.warnings().empty());
    REQUIRE(back.size() == 2);
    const LevelSetInfo& a = back[0].info();
    CHECK(a.name == "object");
    CHECK(a.voxelMm == 1.0);
    CHECK(a.sourceFile == "some dir/bunny.stl");
    CHECK(a.generator == "zomefab 9.9.9");
    CHECK(a.interiorBandMm == 7.5);
    CHECK(a.exteriorBandMm == 0.0);
    CHECK(a.transformMm == object.info().transformMm);
    CHECK(back[0].activeVoxelCount() == object.activeVoxelCount());
    CHECK(back[0].valueMm({3.3, 1.1, 14.0}) == object.valueMm({3.3, 1.1, 14.0}));
    CHECK(back[1].info().name == "interior");
    CHECK(std::isinf(back[1].info().interiorBandMm));
    CHECK(&findLevelSet(back, "interior", "x.vdb") == &back[1]);
    CHECK(&findLevelSet(back, "", "x.vdb") == &back[0]);
    try {
        findLevelSet(back, "shell", "x.vdb");
        FAIL("no error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::InvalidInput);
        CHECK(std::string(e.what()).find("'object', 'interior'") != std::string::npos);
    }
}

TEST_CASE("vdb_file: what is not a millimetre level set is rejected with InvalidInput") {
    CHECK(parseCode("") == ErrorCode::InvalidInput);
    CHECK(parseCode("solid cube\nendsolid cube\n") == ErrorCode::InvalidInput);
    const std::string good =
        serializeVdb({meshToLevelSet(test::makeSphere({0, 0, 0}, 5.0), {}, RunContext::silent())});
    CHECK(parseCode(good.substr(0, good.size() / 2)) == ErrorCode::InvalidInput);  // truncated

    // A fog volume is not a level set.
    openvdb::FloatGrid::Ptr fog = openvdb::FloatGrid::create(0.0f);
    fog->setName("density");
    fog->setGridClass(openvdb::GRID_FOG_VOLUME);
    fog->tree().setValue(openvdb::Coord(1, 2, 3), 1.0f);
    CHECK(parseCode(foreignVdb(fog)) == ErrorCode::InvalidInput);

    // A level set in inches.
    openvdb::FloatGrid::Ptr inches =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(5.0f, {0, 0, 0}, 0.5f);
    inches->setName("object");
    inches->insertMeta("units", openvdb::StringMetadata("inch"));
    CHECK(parseCode(foreignVdb(inches)) == ErrorCode::InvalidInput);
}

TEST_CASE("vdb_file: a foreign level set without metadata is read as millimetres with a warning") {
    openvdb::FloatGrid::Ptr sphere =
        openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(10.0f, {0, 0, 0}, 0.5f);
    sphere->setName("ball");
    RunContext context;
    const std::vector<LevelSet> grids = parseVdb(foreignVdb(sphere), "ball.vdb", context);
    REQUIRE(grids.size() == 1);
    CHECK(grids[0].info().name == "ball");
    CHECK(grids[0].info().voxelMm == 0.5);
    CHECK(grids[0].info().transformMm == Transform4d::identity());
    CHECK(context.warnings().size() == 1);
    CHECK(std::abs(grids[0].valueMm({10, 0, 0})) < 0.05);
}
