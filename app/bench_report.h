#pragma once
// What `raypack bench` writes: an aligned table for people, JSON and CSV
// for scripts (both written atomically).
#include <cstdio>
#include <string>
#include <vector>

#include "app/bench_row.h"

namespace raypack::app {

void print_bench_header(std::FILE* out);
void print_bench_row(std::FILE* out, const BenchRow& row);
void write_bench_json(const std::string& path, const std::vector<BenchRow>& rows);
void write_bench_csv(const std::string& path, const std::vector<BenchRow>& rows);

}  // namespace raypack::app
