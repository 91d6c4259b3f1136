// The ULog reader on the two real PX4 logs of ../shared/testdata/px4_ulog_samples, against numbers
// read from the same files by an independent reader (pyulog at commit 3cf1779, the repository the
// logs come from: ULog(path).data_list, 2026-11-26), and on damaged copies of them.
#include "gyrodrift/io/ulog.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

#include "gyrodrift/common/error.h"
#include "support/test_support.h"

namespace gyrodrift::io {
namespace {

const std::string kSmall = std::string(GYRODRIFT_TESTDATA_DIR) + "/px4_ulog_samples/sample_log_small.ulg";
const std::string kTagged = std::string(GYRODRIFT_TESTDATA_DIR) +
                            "/px4_ulog_samples/sample_logging_tagged_and_default_params.ulg";

std::vector<std::uint8_t> Bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Subscriptions with at least one sample (pyulog's data_list).
std::size_t WithData(const Ulog& log) {
  return static_cast<std::size_t>(std::count_if(log.series.begin(), log.series.end(),
                                                [](const UlogSeries& s) { return s.samples > 0; }));
}

// pyulog's first sample of one sensor_gyro instance: timestamp, x, y, z, temperature.
struct First {
  int instance;
  std::uint64_t timestamp_us;
  double x, y, z, temperature;
};

void ExpectGyros(const Ulog& log, std::size_t samples, const std::vector<First>& firsts) {
  for (const First& f : firsts) {
    const UlogSeries* s = log.Find("sensor_gyro", f.instance);
    ASSERT_NE(s, nullptr) << "instance " << f.instance;
    EXPECT_EQ(s->samples, samples);
    ASSERT_TRUE(s->decoded);
    ASSERT_GE(s->Field("temperature"), 0);
    EXPECT_EQ(s->timestamp_us.front(), f.timestamp_us);
    EXPECT_EQ(s->first_us, f.timestamp_us);
    EXPECT_EQ(s->Column("x").front(), f.x);
    EXPECT_EQ(s->Column("y").front(), f.y);
    EXPECT_EQ(s->Column("z").front(), f.z);
    EXPECT_EQ(s->Column("temperature").front(), f.temperature);
  }
}

TEST(Ulog, ThreeGyroInstancesWithTemperatureAsAnIndependentReaderReadsThem) {
  const Ulog log = ReadUlog(kSmall, {"sensor_gyro"});
  EXPECT_EQ(log.version, 1);
  EXPECT_EQ(log.start_us, 20309082u);
  EXPECT_TRUE(log.warnings.empty());
  EXPECT_EQ(WithData(log), 70u);  // pyulog: 70 entries in data_list
  EXPECT_EQ(log.parameters.size(), 980u);
  EXPECT_EQ(log.dropouts, 1);
  ExpectGyros(log, 6,
              {{0, 21312030, -0.04130320996046066, 0.008715800009667873, 0.029149509966373444,
                40.02537155151367},
               {1, 21311176, 0.017656758427619934, -0.0004261057765688747, -0.006178534124046564,
                28.246023178100586},
               {2, 21311601, -0.0039059696719050407, -0.020728271454572678, -0.003439916530624032,
                29.62611198425293}});
  const UlogSeries& g0 = *log.Find("sensor_gyro", 0);
  EXPECT_EQ(g0.last_us, 26312455u);
  EXPECT_EQ(g0.Column("timestamp_sample")[1], 22311243.0);
  EXPECT_EQ(g0.Column("device_id").back(), 2424842.0);
  EXPECT_EQ(g0.types[static_cast<std::size_t>(g0.Field("x"))], "float");
  // Series not asked for keep their counts but not their samples.
  const UlogSeries* accel = log.Find("sensor_accel", 0);
  ASSERT_NE(accel, nullptr);
  EXPECT_GT(accel->samples, 0u);
  EXPECT_FALSE(accel->decoded);
  EXPECT_THROW(accel->Column("x"), DataError);
  EXPECT_THROW(g0.Column("no_such_field"), DataError);
}

TEST(Ulog, AnAxisNamedTwiceOrADirectoryIsRefused) {
  const Ulog log = ReadUlog(kSmall, {"sensor_gyro"});
  const UlogSeries& g0 = *log.Find("sensor_gyro", 0);
  UlogConversion twice;
  twice.axes = {"x", "y", "x"};
  try {
    UlogColumns(g0, twice);
    ADD_FAILURE() << "an axis named twice was converted";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "axes: 'x' is named twice (one column per axis)");
  }
  const std::string dir = test::TempDir("ulog_directory");
  EXPECT_THROW(ReadUlog(dir), IoError);
}

TEST(Ulog, TaggedLogWithDefaultParameters) {
  const Ulog log = ReadUlog(kTagged, {"*"});
  EXPECT_EQ(log.start_us, 280000u);
  EXPECT_TRUE(log.warnings.empty());
  EXPECT_EQ(WithData(log), 96u);
  EXPECT_EQ(log.parameters.size(), 696u);
  ExpectGyros(log, 11,
              {{0, 976000, -0.013848437927663326, 0.009054748341441154, -0.002130528911948204, 0.0},
               {1, 976000, -0.009958090260624886, 0.012538762763142586, -0.01145199965685606, 0.0},
               {2, 972000, -0.018425989896059036, 0.00732762273401022, 0.006563940085470676,
                0.0}});
  EXPECT_EQ(log.Find("sensor_gyro", 2)->last_us, 10972000u);
  EXPECT_EQ(log.Find("sensor_gyro", 1)->Column("device_id").front(), 1310996.0);
  const std::string listing = DescribeUlog(log);
  EXPECT_NE(listing.find("sensor_gyro"), std::string::npos) << listing;
  EXPECT_NE(listing.find("temperature"), std::string::npos) << listing;
}

TEST(Ulog, TheListingHasALineForEverySeriesHoweverManyFields) {
  // The small log's battery_status has 500+ characters of field names: its line was cut, lost
  // its newline and ran into the next series' line.
  const Ulog log = ReadUlog(kSmall, {"*"});
  const std::string listing = DescribeUlog(log);
  size_t devices = 0;
  for (const UlogSeries& s : log.series)
    devices += s.decoded && s.samples > 0 && s.Field("device_id") >= 0;
  EXPECT_EQ(static_cast<size_t>(std::count(listing.begin(), listing.end(), '\n')),
            2 + log.series.size() + devices);
  for (const UlogSeries& s : log.series) {
    std::string fields;
    for (const std::string& f : s.fields) fields += (fields.empty() ? "" : ",") + f;
    EXPECT_NE(listing.find(fields + "\n"), std::string::npos) << s.topic;
  }
}

TEST(Ulog, ACutFileKeepsWhatCameBeforeTheCutAndSaysWhere) {
  std::vector<std::uint8_t> bytes = Bytes(kSmall);
  const std::size_t cut = bytes.size() - 1000;
  bytes.resize(cut);
  const Ulog log = ParseUlog(bytes, {"sensor_gyro"}, "cut.ulg");
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("cut.ulg: the file ends inside"), std::string::npos)
      << log.warnings[0];
  EXPECT_EQ(log.Find("sensor_gyro", 0)->samples, 6u);
}

TEST(Ulog, DamageInTheDataIsSkippedToTheNextSyncMarkerOrToTheEnd) {
  std::vector<std::uint8_t> bytes = Bytes(kSmall);
  const Ulog whole = ParseUlog(bytes, {}, "whole.ulg");
  std::size_t total = 0;
  for (const UlogSeries& s : whole.series) total += s.samples;
  // Overwrite 4 kB in the middle of the data section with a byte that is no message type (longer
  // than any message of the log, so that a message header falls in it).
  for (std::size_t i = bytes.size() / 2; i < bytes.size() / 2 + 4096; ++i) bytes[i] = 0xff;
  const Ulog damaged = ParseUlog(bytes, {}, "damaged.ulg");
  ASSERT_FALSE(damaged.warnings.empty());
  EXPECT_NE(damaged.warnings[0].find("damaged.ulg: damaged at byte"), std::string::npos)
      << damaged.warnings[0];
  std::size_t kept = 0;
  for (const UlogSeries& s : damaged.series) kept += s.samples;
  EXPECT_LT(kept, total);
  EXPECT_GT(kept, total / 4);
}

TEST(Ulog, ABadHeaderOrDefinitionIsAnErrorNamingTheByte) {
  std::vector<std::uint8_t> bytes = Bytes(kSmall);
  std::vector<std::uint8_t> no_magic = bytes;
  no_magic[1] = 'X';
  try {
    ParseUlog(no_magic, {}, "bad.ulg");
    ADD_FAILURE() << "a file without the magic was read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ulg: not a readable ULog file: no ULog header"),
              std::string::npos)
        << e.what();
  }
  bytes.resize(200);  // inside the definitions
  try {
    ParseUlog(bytes, {}, "short.ulg");
    ADD_FAILURE() << "a file cut in its definitions was read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("of the definitions at byte"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ReadUlog(test::TempDir("ulog") + "/missing.ulg"), IoError);
}


std::vector<std::uint8_t> Le(std::uint64_t v, int n) {
  std::vector<std::uint8_t> out;
  for (int i = 0; i < n; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  return out;
}

std::vector<std::uint8_t> Float(float f) {
  std::uint32_t u = 0;
  std::memcpy(&u, &f, 4);
  return Le(u, 4);
}

std::vector<std::uint8_t> Cat(std::initializer_list<std::vector<std::uint8_t>> parts) {
  std::vector<std::uint8_t> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// A ULog written message by message, for the parts of the format the real logs do not have.
class Builder {
 public:
  Builder() {
    bytes_ = {0x55, 0x4c, 0x6f, 0x67, 0x01, 0x12, 0x35, 0x01};
    Append64(1000);
  }
  void Message(char type, const std::vector<std::uint8_t>& payload) {
    bytes_.push_back(static_cast<std::uint8_t>(payload.size() & 0xff));
    bytes_.push_back(static_cast<std::uint8_t>(payload.size() >> 8));
    bytes_.push_back(static_cast<std::uint8_t>(type));
    bytes_.insert(bytes_.end(), payload.begin(), payload.end());
  }
  void Text(char type, const std::string& text) { Message(type, {text.begin(), text.end()}); }
  void Subscribe(int instance, int id, const std::string& name) {
    Message('A', Cat({{static_cast<std::uint8_t>(instance)}, Le(static_cast<std::uint64_t>(id), 2),
                      std::vector<std::uint8_t>(name.begin(), name.end())}));
  }
  std::vector<std::uint8_t>& bytes() { return bytes_; }
  void Append64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }

 private:
  std::vector<std::uint8_t> bytes_;
};

TEST(Ulog, NestedFormatsArraysPaddingAndAppendedData) {
  Builder b;
  // Flag bits: data appended at an offset filled in below.
  std::vector<std::uint8_t> flags(40, 0);
  flags[8] = 1;
  const std::size_t flags_at = b.bytes().size() + 3;
  b.Message('B', flags);
  b.Text('F', "pair:int16_t a;uint8_t[2] _padding0;float b;");
  b.Text('F', "probe:uint64_t timestamp;pair[2] p;double[2] v;char[4] tag;uint8_t[3] _padding1;");
  b.Message('I', Cat({{15}, std::vector<std::uint8_t>({'c', 'h', 'a', 'r', '[', '2', ']', ' ',
                                                       's', 'y', 's', '_', 'n', 'a', 'm'}),
                      std::vector<std::uint8_t>({'o', 'k'})}));
  b.Message('P', Cat({{11}, std::vector<std::uint8_t>({'f', 'l', 'o', 'a', 't', ' ', 'G', 'A',
                                                       'I', 'N', '1'}),
                      Float(2.5f)}));
  b.Subscribe(1, 7, "probe");
  auto sample = [&](std::uint64_t t, std::int16_t a0, float b1, double v1, bool pad) {
    std::vector<std::uint8_t> p = Cat({Le(7, 2), Le(t, 8), Le(static_cast<std::uint16_t>(a0), 2),
                                       {0, 0}, Float(0.5f), Le(3, 2), {0, 0}, Float(b1)});
    double v[2] = {-1.0, v1};
    std::uint64_t bits[2];
    std::memcpy(bits, v, 16);
    p = Cat({p, Le(bits[0], 8), Le(bits[1], 8), {'a', 'b', 'c', 'd'}});
    if (pad) p = Cat({p, {0, 0, 0}});  // the trailing padding, which a writer may leave out
    b.Message('D', p);
  };
  sample(2000, -5, 1.25f, 3.5, true);
  sample(3000, 6, -2.0f, 4.5, false);
  b.Message('O', Le(10, 2));
  // A message cut by the appended offset, then the appended data.
  b.Message('L', Cat({{6}, Le(0, 8), std::vector<std::uint8_t>(10, 'x')}));
  const std::size_t appended = b.bytes().size() - 5;
  const std::vector<std::uint8_t> offset = Le(appended, 8);
  std::copy(offset.begin(), offset.end(), b.bytes().begin() + static_cast<std::ptrdiff_t>(flags_at + 16));
  b.bytes().resize(appended);
  sample(4000, 7, 9.0f, 5.5, true);

  const Ulog log = ParseUlog(b.bytes(), {"probe"}, "built.ulg");
  EXPECT_TRUE(log.warnings.empty()) << log.warnings.front();
  EXPECT_TRUE(log.appended);
  EXPECT_EQ(log.dropouts, 1);
  EXPECT_EQ(log.info.at("sys_nam"), "ok");
  EXPECT_EQ(log.parameters.at("GAIN1"), 2.5);
  const UlogSeries* s = log.Find("probe", 1);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->fields, (std::vector<std::string>{"timestamp", "p[0].a", "p[0].b", "p[1].a",
                                                 "p[1].b", "v[0]", "v[1]"}));
  ASSERT_EQ(s->samples, 3u);
  EXPECT_EQ(s->timestamp_us, (std::vector<std::uint64_t>{2000, 3000, 4000}));
  EXPECT_EQ(s->Column("p[0].a"), (std::vector<double>{-5, 6, 7}));
  EXPECT_EQ(s->Column("p[1].b"), (std::vector<double>{1.25, -2.0, 9.0}));
  EXPECT_EQ(s->Column("v[1]"), (std::vector<double>{3.5, 4.5, 5.5}));
}

TEST(Ulog, AFormatWithoutFieldsOrACycleIsRefused) {
  Builder b;
  b.Text('F', "loop:loop inner;");
  b.Subscribe(0, 1, "loop");
  EXPECT_THROW(ParseUlog(b.bytes(), {}, "loop.ulg"), DataError);
  Builder c;
  c.Text('F', "bad:float");
  EXPECT_THROW(ParseUlog(c.bytes(), {}, "bad.ulg"), DataError);
  // Arrays of arrays past the largest message are refused before they are laid out.
  Builder d;
  d.Text('F', "a:uint8_t x;");
  d.Text('F', "b:a[60000] y;");
  d.Text('F', "c:b[60000] z;");
  d.Subscribe(0, 1, "c");
  EXPECT_THROW(ParseUlog(d.bytes(), {}, "huge.ulg"), DataError);
}

}  // namespace
}  // namespace gyrodrift::io
