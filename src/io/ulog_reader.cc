// The ULog reader of gyrodrift/io/ulog.h: a byte cursor over the file, the formats flattened to
// numeric leaves once per subscription, then one pass over the messages.
#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <type_traits>

#include "../common/format.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/ulog.h"

namespace gyrodrift::io {
namespace {

using gyrodrift::internal::Format;

constexpr std::array<std::uint8_t, 7> kMagic{0x55, 0x4c, 0x6f, 0x67, 0x01, 0x12, 0x35};
constexpr std::array<std::uint8_t, 8> kSyncMagic{0x2f, 0x73, 0x13, 0x20, 0x25, 0x0c, 0xbb, 0x12};
constexpr std::size_t kHeaderBytes = 16;
constexpr std::size_t kMessageHeaderBytes = 3;
constexpr int kMostNesting = 8;  // nested formats deeper than this are refused (and cycles)
constexpr std::string_view kKnownTypes = "BFIMPQARDLCSO";
constexpr std::size_t kMostBytes = 65535;          // a message's payload cannot be longer
constexpr std::size_t kMostLeaves = 1u << 20;      // numeric fields in all layouts of a log

enum class Base { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kInt64, kUint64, kFloat,
                  kDouble, kBool, kChar };

struct BaseType {
  std::string_view name;
  Base base;
  std::size_t bytes;
};
constexpr std::array<BaseType, 12> kBaseTypes{{{"int8_t", Base::kInt8, 1},
                                               {"uint8_t", Base::kUint8, 1},
                                               {"int16_t", Base::kInt16, 2},
                                               {"uint16_t", Base::kUint16, 2},
                                               {"int32_t", Base::kInt32, 4},
                                               {"uint32_t", Base::kUint32, 4},
                                               {"int64_t", Base::kInt64, 8},
                                               {"uint64_t", Base::kUint64, 8},
                                               {"float", Base::kFloat, 4},
                                               {"double", Base::kDouble, 8},
                                               {"bool", Base::kBool, 1},
                                               {"char", Base::kChar, 1}}};

const BaseType* FindBase(std::string_view name) {
  for (const BaseType& b : kBaseTypes) {
    if (b.name == name) return &b;
  }
  return nullptr;
}

std::uint64_t Little(const std::uint8_t* p, std::size_t bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

// The little-endian bytes at p as a T (an integer or an IEEE float of 2, 4 or 8 bytes).
template <typename T>
T Bits(const std::uint8_t* p) {
  using U = std::conditional_t<sizeof(T) == 8, std::uint64_t,
                               std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint16_t>>;
  const auto u = static_cast<U>(Little(p, sizeof(T)));
  T out;
  std::memcpy(&out, &u, sizeof(T));
  return out;
}

double Value(Base base, const std::uint8_t* p) {
  switch (base) {
    case Base::kInt8: return static_cast<std::int8_t>(p[0]);
    case Base::kUint8: case Base::kBool: case Base::kChar: return p[0];
    case Base::kInt16: return Bits<std::int16_t>(p);
    case Base::kUint16: return Bits<std::uint16_t>(p);
    case Base::kInt32: return Bits<std::int32_t>(p);
    case Base::kUint32: return Bits<std::uint32_t>(p);
    case Base::kInt64: return static_cast<double>(Bits<std::int64_t>(p));
    case Base::kUint64: return static_cast<double>(Bits<std::uint64_t>(p));
    case Base::kFloat: return Bits<float>(p);
    case Base::kDouble: return Bits<double>(p);
  }
  return 0.0;
}

// One field of a format as written: "float[3] accel".
struct RawField {
  std::string type;
  std::size_t count = 1;
  bool array = false;
  std::string name;
};

// A numeric leaf of a flattened format.
struct Leaf {
  std::string name;
  const BaseType* type;
  std::size_t offset;
};

struct Layout {
  std::vector<Leaf> leaves;
  std::size_t bytes = 0;  // of the whole format, padding included
  std::size_t trailing_padding = 0;  // the data message may leave these bytes out
  int timestamp = -1;                // the leaf "timestamp" (uint64_t), or -1
};

// "float[3]" -> ("float", 3, array); false when the count is not a number in [1, 65535].
bool SplitArray(std::string_view text, std::string& type, std::size_t& count, bool& array) {
  const std::size_t open = text.find('[');
  if (open == std::string_view::npos) {
    type = std::string(text);
    count = 1;
    array = false;
    return !type.empty();
  }
  if (text.back() != ']' || open == 0) return false;
  const std::string_view digits = text.substr(open + 1, text.size() - open - 2);
  if (digits.empty() || digits.size() > 5) return false;
  std::size_t n = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return false;
    n = n * 10 + static_cast<std::size_t>(c - '0');
  }
  if (n < 1 || n > 65535) return false;
  type = std::string(text.substr(0, open));
  count = n;
  array = true;
  return true;
}

class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, const std::vector<std::string>& decode,
         const std::string& source)
      : bytes_(bytes), source_(source) {
    for (const std::string& t : decode) {
      if (t == "*") decode_all_ = true;
      decode_.insert(t);
    }
  }

  Ulog Read() {
    ReadHeader();
    std::size_t pos = kHeaderBytes;
    while (pos < bytes_.size()) {
      const std::size_t boundary = NextAppendedOffset(pos);
      if (pos + kMessageHeaderBytes > bytes_.size()) {
        Cut(pos, "a message header");
        break;
      }
      const std::size_t size = Little(&bytes_[pos], 2);
      const char type = static_cast<char>(bytes_[pos + 2]);
      const std::size_t end = pos + kMessageHeaderBytes + size;
      if (end > boundary) {  // the data written before an appended offset stops at it
        pos = boundary;
        continue;
      }
      if (kKnownTypes.find(type) == std::string_view::npos || type == '\0') {
        pos = Damaged(pos, Format("a message of unknown type 0x%02x", bytes_[pos + 2]));
        continue;
      }
      if (end > bytes_.size()) {
        // Past the end: a cut file, unless a sync marker follows (a damaged size).
        if (in_data_ && std::search(bytes_.begin() + static_cast<std::ptrdiff_t>(pos + 1),
                                    bytes_.end(), kSyncMagic.begin(),
                                    kSyncMagic.end()) != bytes_.end()) {
          pos = Damaged(pos, Format("a '%c' message of %zu bytes past the file's end", type, size));
          continue;
        }
        Cut(pos, Format("a '%c' message of %zu bytes", type, size));
        break;
      }
      const std::span<const std::uint8_t> payload = bytes_.subspan(pos + kMessageHeaderBytes, size);
      why_ = "does not fit its definition";
      if (!Message(type, payload, pos)) {
        pos = Damaged(pos, Format("a '%c' message that %s", type, why_.c_str()));
        continue;
      }
      pos = end;
    }
    return std::move(log_);
  }

 private:
  [[noreturn]] void Fail(std::size_t offset, const std::string& what) const {
    throw DataError(Format("%s: not a readable ULog file: %s at byte %zu", source_.c_str(),
                           what.c_str(), offset));
  }

  void ReadHeader() {
    if (bytes_.size() < kHeaderBytes ||
        !std::equal(kMagic.begin(), kMagic.end(), bytes_.begin())) {
      Fail(0, "no ULog header (the magic \"ULog\" 01 12 35)");
    }
    log_.version = bytes_[7];
    log_.start_us = Little(&bytes_[8], 8);
  }

  std::size_t NextAppendedOffset(std::size_t pos) const {
    for (std::size_t offset : appended_offsets_) {
      if (offset > pos) return offset;
    }
    return bytes_.size() + 1 + 65535 + kMessageHeaderBytes;  // past any message
  }

  void Cut(std::size_t pos, const std::string& what) {
    if (!in_data_) Fail(pos, "the file ends inside " + what + " of the definitions");
    log_.warnings.push_back(Format("%s: the file ends inside %s at byte %zu; the %zu bytes before "
                                   "it are read",
                                   source_.c_str(), what.c_str(), pos, pos));
  }

  // Damage at pos: in the definitions an error; in the data the next sync marker, or the end.
  std::size_t Damaged(std::size_t pos, const std::string& what) {
    if (!in_data_) Fail(pos, what + " in the definitions");
    const auto from = bytes_.begin() + static_cast<std::ptrdiff_t>(pos + 1);
    const auto sync = std::search(from, bytes_.end(), kSyncMagic.begin(), kSyncMagic.end());
    if (sync == bytes_.end()) {
      log_.warnings.push_back(Format("%s: damaged at byte %zu (%s) and no sync marker after it: "
                                     "the last %zu bytes are not read",
                                     source_.c_str(), pos, what.c_str(), bytes_.size() - pos));
      return bytes_.size();
    }
    const std::size_t next = static_cast<std::size_t>(sync - bytes_.begin()) + kSyncMagic.size();
    log_.warnings.push_back(Format("%s: damaged at byte %zu (%s): bytes %zu to %zu skipped to the "
                                   "next sync marker",
                                   source_.c_str(), pos, what.c_str(), pos, next));
    return next;
  }

  // One message; false when it cannot be right (damage).
  bool Message(char type, std::span<const std::uint8_t> p, std::size_t pos) {
    switch (type) {
      case 'B': return FlagBits(p, pos);
      case 'F': return FormatMessage(p, pos);
      case 'I': return Info(p, /*parameter=*/false);
      case 'P': return Info(p, /*parameter=*/true);
      case 'A':
        if (!Subscribe(p)) return false;
        in_data_ = true;
        return true;
      case 'R':
        if (p.size() < 2) return false;
        subscriptions_.erase(static_cast<std::uint16_t>(Little(p.data(), 2)));
        return true;
      case 'D': in_data_ = true; return Data(p);
      case 'L': case 'C': in_data_ = true; return true;
      case 'O': ++log_.dropouts; return true;
      default: return true;  // 'M', 'Q', 'S': nothing a conversion needs
    }
  }

  bool FlagBits(std::span<const std::uint8_t> p, std::size_t pos) {
    if (p.size() < 40) return false;
    if ((p[8] & ~1u) != 0 || std::any_of(p.begin() + 9, p.begin() + 16, [](auto b) { return b; })) {
      Fail(pos, "an incompatible flag this reader does not know");
    }
    log_.appended = (p[8] & 1u) != 0;
    if (!log_.appended) return true;
    for (int i = 0; i < 3; ++i) {
      const std::size_t offset = Little(&p[16 + 8 * static_cast<std::size_t>(i)], 8);
      if (offset != 0) appended_offsets_.push_back(offset);
    }
    std::sort(appended_offsets_.begin(), appended_offsets_.end());
    return true;
  }

  bool FormatMessage(std::span<const std::uint8_t> p, std::size_t pos) {
    const std::string text(p.begin(), p.end());
    const std::size_t colon = text.find(':');
    if (colon == std::string::npos || colon == 0) Fail(pos, "a format without a name");
    std::vector<RawField> fields;
    std::size_t start = colon + 1;
    while (start < text.size()) {
      std::size_t semi = text.find(';', start);
      if (semi == std::string::npos) semi = text.size();
      const std::string item = text.substr(start, semi - start);
      start = semi + 1;
      if (item.empty()) continue;
      const std::size_t space = item.find(' ');
      RawField f;
      if (space == std::string::npos || space + 1 >= item.size() ||
          !SplitArray(std::string_view(item).substr(0, space), f.type, f.count, f.array)) {
        Fail(pos, "a format field \"" + item + "\" that is not \"type name\"");
      }
      f.name = item.substr(space + 1);
      fields.push_back(std::move(f));
    }
    formats_[text.substr(0, colon)] = std::move(fields);
    return true;
  }

  bool Info(std::span<const std::uint8_t> p, bool parameter) {
    if (p.empty() || 1 + std::size_t{p[0]} > p.size()) return false;
    const std::string key(p.begin() + 1, p.begin() + 1 + p[0]);
    const std::span<const std::uint8_t> value = p.subspan(1 + std::size_t{p[0]});
    const std::size_t space = key.find(' ');
    if (space == std::string::npos) return false;
    std::string type;
    std::size_t count = 1;
    bool array = false;
    if (!SplitArray(std::string_view(key).substr(0, space), type, count, array)) return false;
    const std::string name = key.substr(space + 1);
    const BaseType* base = FindBase(type);
    if (base == nullptr) return true;  // a type this reader has no use for
    if (base->base == Base::kChar) {
      if (!parameter) log_.info.emplace(name, std::string(value.begin(), value.end()));
      return true;
    }
    if (array || value.size() < base->bytes) return true;
    const double v = Value(base->base, value.data());
    if (parameter) {
      log_.parameters.emplace(name, v);  // the first value: the one the log started with
    } else {
      log_.info.emplace(name, Format("%.17g", v));
    }
    return true;
  }

  // The layout of a format, each computed once; nullptr for a missing type, a cycle, nesting
  // deeper than kMostNesting, a format over the largest message, or past kMostLeaves in all.
  const Layout* FormatLayout(const std::string& name, int depth) {
    if (const auto it = layouts_.find(name); it != layouts_.end()) return &it->second;
    const auto format = formats_.find(name);
    if (format == formats_.end() || depth > kMostNesting || unreadable_.count(name) > 0 ||
        !in_progress_.insert(name).second) {
      return nullptr;
    }
    Layout out;
    bool ok = true;
    for (const RawField& f : format->second) {
      const bool padding = f.name.rfind("_padding", 0) == 0;
      const BaseType* base = FindBase(f.type);
      const Layout* nested = base != nullptr ? nullptr : FormatLayout(f.type, depth + 1);
      const std::size_t element = base != nullptr ? base->bytes : nested ? nested->bytes : 0;
      if ((base == nullptr && nested == nullptr) || out.bytes + element * f.count > kMostBytes) {
        ok = false;
        break;
      }
      if (!padding && (base == nullptr || base->base != Base::kChar)) {
        for (std::size_t i = 0; i < f.count; ++i) {
          const std::size_t at = out.bytes + i * element;
          const std::string field = f.name + (f.array ? Format("[%zu]", i) : std::string());
          if (base != nullptr) {
            out.leaves.push_back({field, base, at});
          } else {
            for (const Leaf& leaf : nested->leaves) {
              out.leaves.push_back({field + "." + leaf.name, leaf.type, at + leaf.offset});
            }
          }
        }
      }
      out.bytes += element * f.count;
      out.trailing_padding = padding ? element * f.count : 0;
    }
    in_progress_.erase(name);
    leaves_ += out.leaves.size();
    if (!ok || leaves_ > kMostLeaves) {
      unreadable_.insert(name);
      return nullptr;
    }
    for (std::size_t i = 0; i < out.leaves.size(); ++i) {
      if (out.leaves[i].name == "timestamp" && out.leaves[i].type->base == Base::kUint64) {
        out.timestamp = static_cast<int>(i);
      }
    }
    return &layouts_.emplace(name, std::move(out)).first->second;
  }

  bool Subscribe(std::span<const std::uint8_t> p) {
    if (p.size() < 4) return false;
    const int instance = p[0];
    const auto id = static_cast<std::uint16_t>(Little(&p[1], 2));
    const std::string name(p.begin() + 3, p.end());
    const Layout* layout = FormatLayout(name, 0);
    if (layout == nullptr) {
      why_ = "subscribes to \"" + name + "\", whose format is missing or not readable";
      return false;
    }
    UlogSeries s;
    s.topic = name;
    s.instance = instance;
    s.decoded = decode_all_ || decode_.count(name) > 0;
    for (const Leaf& leaf : layout->leaves) {
      s.fields.push_back(leaf.name);
      s.types.emplace_back(leaf.type->name);
    }
    log_.series.push_back(std::move(s));
    subscriptions_[id] = {log_.series.size() - 1, layout};
    return true;
  }

  bool Data(std::span<const std::uint8_t> p) {
    if (p.size() < 2) return false;
    const auto it = subscriptions_.find(static_cast<std::uint16_t>(Little(p.data(), 2)));
    if (it == subscriptions_.end()) {
      why_ = Format("names the message id %u, never subscribed", static_cast<unsigned>(Little(p.data(), 2)));
      return false;
    }
    const Layout& layout = *it->second.layout;
    const std::span<const std::uint8_t> data = p.subspan(2);
    if (data.size() + layout.trailing_padding < layout.bytes || data.size() > layout.bytes) {
      return false;
    }
    UlogSeries& s = log_.series[it->second.series];
    std::uint64_t t = 0;
    if (layout.timestamp >= 0) {
      t = Little(&data[layout.leaves[static_cast<std::size_t>(layout.timestamp)].offset], 8);
      if (s.samples == 0) s.first_us = t;
      s.last_us = t;
    }
    ++s.samples;
    if (!s.decoded) return true;
    s.timestamp_us.push_back(t);
    for (const Leaf& leaf : layout.leaves) s.values.push_back(Value(leaf.type->base, &data[leaf.offset]));
    return true;
  }

  struct Subscription {
    std::size_t series;
    const Layout* layout;  // in layouts_
  };

  std::span<const std::uint8_t> bytes_;
  const std::string& source_;
  std::set<std::string> decode_;
  bool decode_all_ = false;
  bool in_data_ = false;
  std::string why_;  // why the last message was refused
  std::vector<std::size_t> appended_offsets_;
  std::map<std::string, std::vector<RawField>> formats_;
  std::map<std::string, Layout> layouts_;  // node-based: the pointers of subscriptions_ stay valid
  std::set<std::string> in_progress_;      // the formats being laid out (a cycle)
  std::set<std::string> unreadable_;       // formats refused once
  std::size_t leaves_ = 0;                 // in all layouts
  std::map<std::uint16_t, Subscription> subscriptions_;
  Ulog log_;
};

}  // namespace

int UlogSeries::Field(std::string_view name) const {
  const auto it = std::find(fields.begin(), fields.end(), name);
  return it == fields.end() ? -1 : static_cast<int>(it - fields.begin());
}

std::vector<double> UlogSeries::Column(std::string_view name) const {
  const int f = Field(name);
  if (f < 0) {
    throw DataError(Format("%s (instance %d) has no field \"%.*s\"", topic.c_str(), instance,
                           static_cast<int>(name.size()), name.data()));
  }
  if (!decoded) {
    throw DataError(Format("%s (instance %d) was not decoded", topic.c_str(), instance));
  }
  std::vector<double> out(samples);
  for (std::size_t i = 0; i < samples; ++i) out[i] = values[i * fields.size() + static_cast<std::size_t>(f)];
  return out;
}

const UlogSeries* Ulog::Find(std::string_view topic, int instance) const {
  for (const UlogSeries& s : series) {
    if (s.topic == topic && s.instance == instance) return &s;
  }
  return nullptr;
}

Ulog ParseUlog(std::span<const std::uint8_t> bytes, const std::vector<std::string>& decode,
               const std::string& source) {
  return Reader(bytes, decode, source).Read();
}

Ulog ReadUlog(const std::string& path, const std::vector<std::string>& decode) {
  RequireNotDirectory(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open " + path + " for reading");
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError("cannot read " + path);
  return ParseUlog(bytes, decode, path);
}

std::string DescribeUlog(const Ulog& log) {
  std::string out = Format("ULog version %d, %zu series, %zu parameters, %d dropouts%s\n",
                           log.version, log.series.size(), log.parameters.size(), log.dropouts,
                           log.appended ? ", data appended" : "");
  out += Format("%-32s %8s %9s %10s %9s  %s\n", "topic", "instance", "samples", "duration_s",
                "rate_hz", "fields");
  for (const UlogSeries& s : log.series) {
    const double span = 1e-6 * static_cast<double>(s.last_us - s.first_us);
    const double rate = s.samples > 1 && span > 0.0 ? static_cast<double>(s.samples - 1) / span : 0.0;
    std::string fields;
    for (const std::string& f : s.fields) fields += (fields.empty() ? "" : ",") + f;
    out += Format("%-32s %8d %9zu %10.3f %9.3g  %s\n", s.topic.c_str(), s.instance, s.samples,
                  span, rate, fields.c_str());
  }
  // The sensors' ids, which PX4's calibration parameters name (export --format px4).
  for (const UlogSeries& s : log.series) {
    if (!s.decoded || s.samples == 0 || s.Field("device_id") < 0) continue;
    out += Format("device_id of %s instance %d: %.0f\n", s.topic.c_str(), s.instance,
                  s.values[static_cast<size_t>(s.Field("device_id"))]);
  }
  return out;
}

std::vector<const UlogSeries*> SeriesWithSamples(const Ulog& log, const std::string& source,
                                                 const std::string& topic, int instance) {
  std::vector<const UlogSeries*> out;
  for (const UlogSeries& s : log.series) {
    if (s.topic == topic && (instance < 0 || s.instance == instance) && s.samples > 0) {
      out.push_back(&s);
    }
  }
  if (out.empty()) {
    throw DataError(Format("%s: no samples of %s%s (gyrodrift convert %s --list shows what the "
                           "log holds)",
                           source.c_str(), topic.c_str(),
                           instance < 0 ? "" : Format(" instance %d", instance).c_str(),
                           source.c_str()));
  }
  return out;
}

std::vector<CsvColumn> UlogColumns(const UlogSeries& series, const UlogConversion& conversion) {
  const std::string name = Format("%s (instance %d)", series.topic.c_str(), series.instance);
  if (series.samples == 0) throw DataError(name + " has no samples");
  if (series.Field("timestamp") < 0) throw DataError(name + " has no timestamp field");
  auto column = [&](const std::string& field) {
    const std::vector<double> v = series.Column(field);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  };
  for (size_t a = 0; a < conversion.axes.size(); ++a) {
    for (size_t b = 0; b < a; ++b) {
      if (conversion.axes[a] == conversion.axes[b]) {
        throw UsageError("axes: '" + conversion.axes[a] + "' is named twice (one column per axis)");
      }
    }
  }
  std::vector<CsvColumn> out;
  Eigen::VectorXd time(static_cast<Eigen::Index>(series.samples));
  for (std::size_t i = 0; i < series.samples; ++i) {
    time[static_cast<Eigen::Index>(i)] = 1e-6 * static_cast<double>(series.timestamp_us[i]);
  }
  out.push_back({"time_s", std::move(time)});
  const double factor = allan::ToDegPerHour(allan::RateUnit::kRadPerSecond) /
                        allan::ToDegPerHour(conversion.units);
  for (const std::string& axis : conversion.axes) {
    out.push_back({axis + "_" + allan::ToString(conversion.units), column(axis) * factor});
  }
  if (!conversion.temperature.empty()) {
    out.push_back({"temperature_c", column(conversion.temperature)});
  }
  return out;
}

}  // namespace gyrodrift::io
