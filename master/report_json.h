#pragma once
// run.json's text: the report as Protobuf's JSON printer writes it, but with
// 64-bit integers as numbers ("frames": 300), where the printer quotes them
// ("frames": "300", proto3's rule for readers that hold numbers as doubles).
// Counts and nanosecond offsets stay below 2^53, so every reader gets them
// exactly, and tools like jq compare them as numbers. Protobuf's parser reads
// both forms.

#include <string>

#include "optique/report.pb.h"

namespace optique::master {

[[nodiscard]] std::string report_json(const report::RunReport& report);

}  // namespace optique::master
