// The error family and the validation helpers of check.h implemented beside it (error.cc): every
// kind maps to its documented exit code (docs/errors.md), an OptionError reads "option = value:
// must be rule" and keeps its parts, and each Require* helper draws its line where its comment
// says, NaN and infinities included.
#include "gyrodrift/common/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

#include "gyrodrift/common/check.h"

namespace gyrodrift {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The message of the OptionError `call` throws, or "" when it throws none.
template <typename F>
std::string OptionMessage(F&& call) {
  try {
    call();
  } catch (const OptionError& e) {
    return e.what();
  }
  return "";
}

// The message of the DataError `call` throws, or "" when it throws none.
template <typename F>
std::string DataMessage(F&& call) {
  try {
    call();
  } catch (const DataError& e) {
    return e.what();
  }
  return "";
}

TEST(ExitCode, EachKindHasItsDocumentedCode) {
  EXPECT_EQ(ExitCode(ErrorKind::kUsage), 2);
  EXPECT_EQ(ExitCode(ErrorKind::kData), 3);
  EXPECT_EQ(ExitCode(ErrorKind::kIo), 4);
  EXPECT_EQ(ExitCode(ErrorKind::kUnitsFailed), 5);
  // A kind the switch does not know is an internal error (1), never success.
  EXPECT_EQ(ExitCode(static_cast<ErrorKind>(99)), 1);
}

TEST(Error, EachTypeCarriesItsKindAndIsCaughtAsError) {
  // The CLI catches gyrodrift::Error and asks its kind: each concrete type must say its own.
  auto kind_of = [](auto&& thrower) {
    try {
      thrower();
    } catch (const Error& e) {
      return e.kind();
    }
    ADD_FAILURE() << "nothing thrown";
    return static_cast<ErrorKind>(-1);
  };
  EXPECT_EQ(kind_of([] { throw UsageError("u"); }), ErrorKind::kUsage);
  EXPECT_EQ(kind_of([] { throw OptionError("a", "b", "c"); }), ErrorKind::kUsage);
  EXPECT_EQ(kind_of([] { throw DataError("d"); }), ErrorKind::kData);
  EXPECT_EQ(kind_of([] { throw IoError("i"); }), ErrorKind::kIo);
  EXPECT_EQ(kind_of([] { throw FleetFailure("f"); }), ErrorKind::kUnitsFailed);
  // An OptionError is a UsageError (callers that catch usage mistakes see it).
  EXPECT_THROW(throw OptionError("a", "b", "c"), UsageError);
  EXPECT_STREQ(DataError("the message").what(), "the message");
}

TEST(OptionError, MessageHasTheDocumentedShapeAndKeepsItsParts) {
  const OptionError e("sifting.s_number", "0", "an integer in [1, 1000]");
  EXPECT_STREQ(e.what(), "sifting.s_number = 0: must be an integer in [1, 1000]");
  EXPECT_EQ(e.option(), "sifting.s_number");
  EXPECT_EQ(e.value(), "0");
  EXPECT_EQ(e.rule(), "an integer in [1, 1000]");
}

TEST(FormatValue, IsTheShortestTextThatRoundTrips) {
  EXPECT_EQ(FormatValue(0.1), "0.1");
  EXPECT_EQ(FormatValue(-2.0), "-2");
  EXPECT_EQ(FormatValue(1e300), "1e+300");
  for (double v : {1.0 / 3.0, 6.02214076e23, 5e-324, -0.0}) {
    EXPECT_EQ(std::strtod(FormatValue(v).c_str(), nullptr), v) << FormatValue(v);
  }
  EXPECT_EQ(FormatValue(kNan), "nan");
  EXPECT_EQ(FormatValue(-kInf), "-inf");
}

TEST(RequireInRange, BoundsAreInclusiveAndNanIsRefused) {
  EXPECT_NO_THROW(RequireInRange("split", 0.1, 0.1, 0.95));
  EXPECT_NO_THROW(RequireInRange("split", 0.95, 0.1, 0.95));
  EXPECT_EQ(OptionMessage([] { RequireInRange("split", 0.96, 0.1, 0.95); }),
            "split = 0.96: must be in [0.1, 0.95]");
  EXPECT_EQ(OptionMessage([] { RequireInRange("split", 0.0999, 0.1, 0.95); }),
            "split = 0.0999: must be in [0.1, 0.95]");
  // NaN compares false with everything: a naive `v < lo || v > hi` would let it through.
  EXPECT_EQ(OptionMessage([] { RequireInRange("split", kNan, 0.1, 0.95); }),
            "split = nan: must be in [0.1, 0.95]");
  EXPECT_EQ(OptionMessage([] { RequireInRange("split", kInf, 0.1, 0.95); }),
            "split = inf: must be in [0.1, 0.95]");
}

TEST(RequirePositive, RefusesZeroNegativeNanAndInfinity) {
  EXPECT_NO_THROW(RequirePositive("rate_hz", 5e-324));
  EXPECT_NO_THROW(RequirePositive("rate_hz", 1e308));
  for (double v : {0.0, -0.0, -1.0, kNan, kInf, -kInf}) {
    EXPECT_EQ(OptionMessage([v] { RequirePositive("rate_hz", v); }),
              "rate_hz = " + FormatValue(v) + ": must be a finite number > 0")
        << v;
  }
}

TEST(RequireNonNegative, AcceptsZeroAndRefusesNegativeNanAndInfinity) {
  EXPECT_NO_THROW(RequireNonNegative("noise", 0.0));
  EXPECT_NO_THROW(RequireNonNegative("noise", -0.0));  // -0 == 0
  EXPECT_NO_THROW(RequireNonNegative("noise", 3.5));
  for (double v : {-5e-324, -1.0, kNan, kInf}) {
    EXPECT_EQ(OptionMessage([v] { RequireNonNegative("noise", v); }),
              "noise = " + FormatValue(v) + ": must be a finite number >= 0")
        << v;
  }
}

TEST(ThrowOption, ThrowsTheOptionErrorItNames) {
  try {
    ThrowOption("ensemble_size", "0", "an integer in [1, 100000]");
    FAIL() << "nothing thrown";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "ensemble_size");
    EXPECT_EQ(e.value(), "0");
    EXPECT_EQ(e.rule(), "an integer in [1, 100000]");
  }
}

TEST(RequireFiniteSignal, NamesTheCountOrTheFirstBadSampleOneBased) {
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(5, 0.0, 4.0);
  EXPECT_NO_THROW(RequireFiniteSignal("rate_dph", x, 5));
  EXPECT_EQ(DataMessage([&] { RequireFiniteSignal("rate_dph", x, 6); }),
            "rate_dph has 5 samples: at least 6 are needed");
  x[2] = kNan;
  x[4] = kInf;
  // The first bad sample, counted from 1 as a user counts rows.
  EXPECT_EQ(DataMessage([&] { RequireFiniteSignal("rate_dph", x, 1); }),
            "rate_dph sample 3 is nan: every sample must be finite");
  x[2] = 0.0;
  EXPECT_EQ(DataMessage([&] { RequireFiniteSignal("rate_dph", x, 1); }),
            "rate_dph sample 5 is inf: every sample must be finite");
  // Too short is reported before non-finite samples are looked for.
  EXPECT_EQ(DataMessage([&] { RequireFiniteSignal("rate_dph", x, 10); }),
            "rate_dph has 5 samples: at least 10 are needed");
}

TEST(RequireFiniteSignal, RefusesMagnitudesNoInstrumentLogs) {
  Eigen::VectorXd x = Eigen::VectorXd::Constant(4, -kLargestSampleMagnitude);
  x[1] = kLargestSampleMagnitude;
  EXPECT_NO_THROW(RequireFiniteSignal("rate_dph", x, 4));  // the bound itself is usable
  x[3] = -1e200;                                           // finite, but its square overflows
  EXPECT_EQ(DataMessage([&] { RequireFiniteSignal("rate_dph", x, 1); }),
            "rate_dph sample 4 is -1e+200: no instrument logs a magnitude above 1e+100 (the "
            "models' sums of squares would overflow)");
  EXPECT_EQ(DataMessage([] { RequireUsableSample("target", 7, kNan, /*logged=*/true); }),
            "target sample 7 (logged) is nan: every logged sample must be finite");
  EXPECT_EQ(DataMessage([] { RequireUsableSample("target", 7, 2e100, /*logged=*/true); }),
            "target sample 7 (logged) is 2e+100: no instrument logs a magnitude above 1e+100 (the "
            "models' sums of squares would overflow)");
}

TEST(RequireVaryingSignal, RefusesOnlyAConstantSignal) {
  EXPECT_NO_THROW(RequireVaryingSignal("t", Eigen::VectorXd(), "nothing to fit"));
  Eigen::VectorXd x = Eigen::VectorXd::Constant(4, 20.5);
  EXPECT_EQ(DataMessage([&] { RequireVaryingSignal("temperature_c", x, "nothing to fit"); }),
            "temperature_c is constant (every sample is 20.5): nothing to fit");
  // One differing sample anywhere, the last included, is enough.
  x[3] = 20.25;
  EXPECT_NO_THROW(RequireVaryingSignal("temperature_c", x, "nothing to fit"));
  EXPECT_EQ(DataMessage([] {
              RequireVaryingSignal("one", Eigen::VectorXd::Constant(1, 1.0), "too little");
            }),
            "one is constant (every sample is 1): too little");
}

TEST(ValidateNested, PrefixesTheFieldAndKeepsValueAndRule) {
  const OptionError inner("max_sifts", "0", "an integer in [1, 10000]");
  try {
    ValidateNested("sifting", [&] { throw inner; });
    FAIL() << "nothing thrown";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "sifting.max_sifts");
    EXPECT_STREQ(e.what(), "sifting.max_sifts = 0: must be an integer in [1, 10000]");
  }
  // Other errors pass through untouched.
  EXPECT_THROW(ValidateNested("sifting", [] { throw DataError("x"); }), DataError);
  EXPECT_NO_THROW(ValidateNested("sifting", [] {}));
}

TEST(ValidateAsSettings, RenamesOnlyTheListedFields) {
  auto refused = [](const std::string& option) {
    try {
      ValidateAsSettings({{"decomposition.ensemble_size", "ensemble"}},
                         [&] { ThrowOption(option, "0", "an integer in [1, 100000]"); });
    } catch (const OptionError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refused("decomposition.ensemble_size"),
            "ensemble = 0: must be an integer in [1, 100000]");
  // A field without a setting keeps the library's name.
  EXPECT_EQ(refused("decomposition.noise"),
            "decomposition.noise = 0: must be an integer in [1, 100000]");
}

}  // namespace
}  // namespace gyrodrift
