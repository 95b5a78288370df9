// Tests of reflected technique parameters: defaults, conversions, range and enum checks, the errors users see, and the
// nearest-name suggestions used across Tyndall.
#include "tyndall/core/params.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace tyndall {
namespace {

ParamInfo makeInfo(std::string name, ParamType type, double min, double max, ParamValue defaultValue,
                   std::vector<std::string> enumValues = {}) {
    ParamInfo info;
    info.name = std::move(name);
    info.type = type;
    info.min = min;
    info.max = max;
    info.defaultValue = std::move(defaultValue);
    info.enumValues = std::move(enumValues);
    return info;
}

ParamSet exampleParams() {
    ParamInfo sigma = makeInfo("sigma", ParamType::Float, 0.0, 10.0, 1.0);
    sigma.unit = "1/m";
    return ParamSet({
        sigma,
        makeInfo("spp", ParamType::Int, 1.0, 4096.0, std::int64_t{16}),
        makeInfo("jitter", ParamType::Bool, 0.0, 1.0, true),
        makeInfo("sampling", ParamType::Enum, 0.0, 1.0, std::string("mis"), {"mis", "light", "phase"}),
        makeInfo("tint", ParamType::Rgb, 0.0, 1.0, Rgb(0.5)),
    });
}

// The InputError thrown by `set`, or a failure when there is none.
InputError setError(ParamSet& params, const std::string& name, const ParamValue& value) {
    try {
        params.set(name, value);
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "setting " << name << " = " << toString(value) << " did not throw";
    return InputError("no error");
}

bool contains(const std::string& text, const std::string& phrase) {
    return text.find(phrase) != std::string::npos;
}

TEST(ParamsSet, StartsAtTheDefaults) {
    const ParamSet params = exampleParams();
    EXPECT_EQ(params.getFloat("sigma"), 1.0);
    EXPECT_EQ(params.getInt("spp"), 16);
    EXPECT_TRUE(params.getBool("jitter"));
    EXPECT_EQ(params.getEnum("sampling"), "mis");
    EXPECT_EQ(params.getRgb("tint"), Rgb(0.5));
    EXPECT_EQ(params.values().size(), 5u);
    ASSERT_NE(params.find("spp"), nullptr);
    EXPECT_EQ(params.find("spp")->type, ParamType::Int);
    EXPECT_EQ(params.find("nope"), nullptr);
}

TEST(ParamsSet, SetsValuesOfEveryType) {
    ParamSet params = exampleParams();
    params.set("sigma", 2.5);
    params.set("spp", std::int64_t{64});
    params.set("jitter", false);
    params.set("sampling", std::string("light"));
    params.set("tint", Rgb(0.1, 0.2, 0.3));
    EXPECT_EQ(params.getFloat("sigma"), 2.5);
    EXPECT_EQ(params.getInt("spp"), 64);
    EXPECT_FALSE(params.getBool("jitter"));
    EXPECT_EQ(params.getEnum("sampling"), "light");
    EXPECT_EQ(params.getRgb("tint"), Rgb(0.1, 0.2, 0.3));
}

TEST(ParamsSet, ConvertsBetweenIntAndFloatWhenExact) {
    ParamSet params = exampleParams();
    params.set("sigma", std::int64_t{3});
    EXPECT_EQ(params.getFloat("sigma"), 3.0);
    params.set("spp", 128.0);
    EXPECT_EQ(params.getInt("spp"), 128);
    const InputError e = setError(params, "spp", 2.5);
    EXPECT_EQ(e.where().field, "spp");
    EXPECT_TRUE(contains(e.message(), "an integer in [1, 4096]")) << e.what();
}

TEST(ParamsSet, AcceptsOneNumberAsGreyRgb) {
    ParamSet params = exampleParams();
    params.set("tint", 0.25);
    EXPECT_EQ(params.getRgb("tint"), Rgb(0.25));
}

TEST(ParamsSet, RejectsValuesOutOfRange) {
    ParamSet params = exampleParams();
    const InputError high = setError(params, "sigma", 11.0);
    EXPECT_EQ(high.where().field, "sigma");
    EXPECT_TRUE(contains(high.message(), "a number in [0, 10] 1/m, got 11")) << high.what();
    const InputError low = setError(params, "spp", std::int64_t{0});
    EXPECT_TRUE(contains(low.message(), "got 0")) << low.what();
    const InputError nan = setError(params, "sigma", std::nan(""));
    EXPECT_TRUE(contains(nan.message(), "got nan")) << nan.what();
    EXPECT_EQ(params.getFloat("sigma"), 1.0) << "a rejected value must not change the set";
}

TEST(ParamsSet, RejectsRgbWithAComponentOutOfRange) {
    ParamSet params = exampleParams();
    const InputError e = setError(params, "tint", Rgb(0.5, 1.5, 0.5));
    EXPECT_EQ(e.where().field, "tint");
    EXPECT_TRUE(contains(e.message(), "each component in [0, 1]")) << e.what();
}

TEST(ParamsSet, RejectsEnumValuesNotDeclared) {
    ParamSet params = exampleParams();
    const InputError e = setError(params, "sampling", std::string("equiangular"));
    EXPECT_EQ(e.where().field, "sampling");
    EXPECT_TRUE(contains(e.message(), "one of mis, light, phase, got 'equiangular'")) << e.what();
}

TEST(ParamsSet, RejectsValuesOfTheWrongType) {
    ParamSet params = exampleParams();
    const InputError e = setError(params, "sigma", true);
    EXPECT_EQ(e.where().field, "sigma");
    EXPECT_TRUE(contains(e.message(), "got a boolean true")) << e.what();
    EXPECT_TRUE(contains(setError(params, "jitter", std::int64_t{1}).message(), "true or false"));
    EXPECT_TRUE(contains(setError(params, "sampling", 1.0).message(), "one of mis"));
}

TEST(ParamsSet, SuggestsTheNearestNameForUnknownParameters) {
    ParamSet params = exampleParams();
    const InputError e = setError(params, "SPX", std::int64_t{4});
    EXPECT_EQ(e.where().field, "SPX");
    EXPECT_TRUE(contains(e.message(), "unknown parameter 'SPX'; did you mean 'spp'?")) << e.what();
    const InputError far = setError(params, "completelyDifferent", 1.0);
    EXPECT_TRUE(contains(far.message(), "known parameters: sigma, spp, jitter, sampling, tint")) << far.what();
}

TEST(ParamsSet, GettersOfTheWrongTypeBreakTheContract) {
    const ParamSet params = exampleParams();
    EXPECT_THROW(params.getInt("sigma"), ContractError);
    EXPECT_THROW(params.getFloat("spp"), ContractError);
    EXPECT_THROW(params.getBool("tint"), ContractError);
    EXPECT_THROW(params.getEnum("jitter"), ContractError);
    EXPECT_THROW(params.getRgb("sampling"), ContractError);
    EXPECT_THROW(params.get("missing"), ContractError);
}

TEST(ParamsSet, InvalidDeclarationsBreakTheContract) {
    EXPECT_THROW(ParamSet({makeInfo("x", ParamType::Int, 0.0, 1.0, 0.5)}), ContractError);
    EXPECT_THROW(ParamSet({makeInfo("x", ParamType::Float, 0.0, 1.0, 2.0)}), ContractError);
    EXPECT_THROW(
        ParamSet({makeInfo("x", ParamType::Float, 0.0, 1.0, 0.5), makeInfo("x", ParamType::Float, 0.0, 1.0, 0.5)}),
        ContractError);
}

TEST(ParamsToString, NamesTypesAndFormatsValues) {
    EXPECT_STREQ(toString(ParamType::Float), "float");
    EXPECT_STREQ(toString(ParamType::Int), "int");
    EXPECT_STREQ(toString(ParamType::Bool), "bool");
    EXPECT_STREQ(toString(ParamType::Enum), "enum");
    EXPECT_STREQ(toString(ParamType::Rgb), "rgb");
    EXPECT_EQ(toString(ParamValue(0.1)), "0.1");
    EXPECT_EQ(toString(ParamValue(std::int64_t{-7})), "-7");
    EXPECT_EQ(toString(ParamValue(false)), "false");
    EXPECT_EQ(toString(ParamValue(std::string("mis"))), "mis");
    EXPECT_EQ(toString(ParamValue(Rgb(1.0, 0.5, 0.25))), "[1, 0.5, 0.25]");
}

TEST(ParamsNearestName, FindsTheClosestNameIgnoringCase) {
    const std::vector<std::string> known = {"sigma_s", "sigma_a", "phase", "extinction"};
    EXPECT_EQ(nearestName("sigma_S", known), "sigma_s");
    EXPECT_EQ(nearestName("SIGMA_A", known), "sigma_a");
    EXPECT_EQ(nearestName("phse", known), "phase");
    EXPECT_EQ(nearestName("extintcion", known), "extinction");
}

TEST(ParamsNearestName, ReturnsNothingWhenNoNameIsClose) {
    const std::vector<std::string> known = {"sigma_s", "phase"};
    EXPECT_EQ(nearestName("radiance", known), "");
    EXPECT_EQ(nearestName("anything", {}), "");
    // Short names allow a distance of 2, long ones a third of their length.
    EXPECT_EQ(nearestName("ab", {"xy"}), "xy");
    EXPECT_EQ(nearestName("abc", {"xyz"}), "");
    EXPECT_EQ(nearestName("multiplierMinimum", {"multiplierMin"}), "multiplierMin");
}

}  // namespace
}  // namespace tyndall
