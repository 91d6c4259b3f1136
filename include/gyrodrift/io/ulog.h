// Reading PX4 ULog files, the autopilot's binary log, written from the format's specification
// (PX4 user guide, "ULog File Format", file version 1).
//
// A file is a 16-byte header (the magic "ULog" 01 12 35, the version, the start time in us), then
// messages of a 3-byte header (payload size, uint16 little-endian; type, one ASCII letter) and a
// payload. The definitions section holds the flag bits ('B'), the message formats ('F': "name:type
// field;type field;..." with the base types, arrays "float[3]", nested formats and "_padding"
// fields), information ('I', 'M') and parameters ('P', 'Q'); the data section the subscriptions
// ('A': a message id for a format name and a multi-instance id), the data ('D': the message id,
// then the fields packed, no alignment, the trailing padding possibly left out), log strings
// ('L', 'C'), sync markers ('S') and dropouts ('O'). A log may have data appended after its end
// (flag bit 0 of the incompatible flags, with up to three file offsets): the data written before
// an offset stops at it, and reading goes on from it.
//
// Damage: a header or definition that cannot be read is a DataError naming its byte offset. In
// the data section a message that cannot be right (a type that is not one of the above, a data
// message for an id never subscribed, or shorter than its format) is damage: the reader looks for
// the next sync marker and goes on after it, or stops; a file cut inside a message stops there.
// Each is a warning naming the byte offsets skipped, and what was read before stays read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/io/csv.h"

namespace gyrodrift::io {

// The largest multi-instance id: ULog writes it in one byte.
inline constexpr int kMaxUlogInstance = 255;

// One multi-instance subscription of a topic: its numeric fields (arrays and nested formats
// flattened: "accel[0]", "esc.rpm"; strings and padding left out) and, when decoded, its samples.
struct UlogSeries {
  std::string topic;  // the format's name, "sensor_gyro"
  int instance = 0;   // the multi-instance id
  std::vector<std::string> fields;
  std::vector<std::string> types;  // per field: "float", "uint64_t", ...
  std::size_t samples = 0;         // data messages read
  std::uint64_t first_us = 0, last_us = 0;  // the first and the last time stamp (the "timestamp" field)
  bool decoded = false;
  std::vector<std::uint64_t> timestamp_us;  // per sample, when decoded
  std::vector<double> values;               // samples x fields, row-major, when decoded

  // The index of a field, or -1.
  int Field(std::string_view name) const;
  // One field of every sample (decoded series only); DataError naming the field if absent.
  std::vector<double> Column(std::string_view name) const;
};

struct Ulog {
  int version = 0;
  std::uint64_t start_us = 0;  // the header's time stamp
  std::map<std::string, std::string> info;  // 'I' messages: key name -> value as text
  std::map<std::string, double> parameters;  // the first value of every 'P' parameter
  std::vector<UlogSeries> series;            // in the order of their subscriptions
  int dropouts = 0;
  bool appended = false;               // the file has data appended
  std::vector<std::string> warnings;   // damage skipped, with byte offsets

  // The series of a topic and instance, or nullptr.
  const UlogSeries* Find(std::string_view topic, int instance) const;
};

// Reads a ULog file; the series of the topics named in `decode` keep their samples (every topic
// with "*"), the others only their counts and time span. IoError for a missing or unreadable
// file, DataError as in the header comment.
Ulog ReadUlog(const std::string& path, const std::vector<std::string>& decode = {});
// The same from bytes in memory; `source` names them in messages.
Ulog ParseUlog(std::span<const std::uint8_t> bytes, const std::vector<std::string>& decode,
               const std::string& source);

// A table of the log's series for `gyrodrift convert --list`: topic, instance, samples, duration,
// mean rate and fields, one line each; then, for each decoded series with a device_id field, its
// first sample's id ("device_id of sensor_gyro instance 0: 2490378").
std::string DescribeUlog(const Ulog& log);

// What a conversion writes of one series: time_s (its time stamps, s), the axes in `units` as
// <axis>_<units>, and the temperature as temperature_c.
struct UlogConversion {
  std::string topic = "sensor_gyro";
  std::vector<std::string> axes{"x", "y", "z"};  // fields in rad/s (PX4's sensor_gyro)
  std::string temperature = "temperature";         // a field in degC; empty: none
  allan::RateUnit units = allan::RateUnit::kDegPerHour;
  bool operator==(const UlogConversion&) const = default;
};
// The series of `topic` with samples: the one of `instance`, or every instance when instance < 0.
// DataError when there is none, naming the log (`source`) and what was asked.
std::vector<const UlogSeries*> SeriesWithSamples(const Ulog& log, const std::string& source,
                                                 const std::string& topic, int instance);
// The columns of a decoded series. DataError naming a missing field, a series without samples or
// a "timestamp" field.
std::vector<CsvColumn> UlogColumns(const UlogSeries& series, const UlogConversion& conversion);

}  // namespace gyrodrift::io
