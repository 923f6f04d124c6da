// ns per decode and encode of the PMU codec (Google Benchmark).
#include <benchmark/benchmark.h>

#include "pmu/codec/candump.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/codec/encode.hpp"

namespace {

using namespace pmu::codec;

void BM_DecodeVoltages(benchmark::State& state) {
  const CanFrame f = *encode_voltages({24.0, 28.0, 12.0, 6.0, 16.8, 16.7, 48.4}, 1);
  for (auto _ : state) benchmark::DoNotOptimize(decode(f));
}
BENCHMARK(BM_DecodeVoltages);

void BM_DecodeStatus(benchmark::State& state) {
  Status s;
  s.generator_rpm = 6000;
  s.outputs = 3;
  const CanFrame f = *encode_status(s, 1);
  for (auto _ : state) benchmark::DoNotOptimize(decode(f, FirmwareVersion{1, 16}));
}
BENCHMARK(BM_DecodeStatus);

void BM_DecodeForeign(benchmark::State& state) {
  CanFrame f;
  f.id = 0x18FEF100;
  f.extended = true;
  f.length = 8;
  for (auto _ : state) benchmark::DoNotOptimize(decode(f));
}
BENCHMARK(BM_DecodeForeign);

void BM_EncodeSetParameter(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(encode_set(Parameter::AvionicsVoltage, 24.0, 1));
}
BENCHMARK(BM_EncodeSetParameter);

void BM_EncodeVoltages(benchmark::State& state) {
  const Voltages v{24.0, 28.0, 12.0, 6.0, 16.8, 16.7, 48.4};
  for (auto _ : state) benchmark::DoNotOptimize(encode_voltages(v, 1));
}
BENCHMARK(BM_EncodeVoltages);

void BM_ParseCandumpLine(benchmark::State& state) {
  const std::string_view line = "(1700000000.000000) can0 1E000001#F08C3C1EA8A779";
  for (auto _ : state) benchmark::DoNotOptimize(parse_candump_line(line));
}
BENCHMARK(BM_ParseCandumpLine);

}  // namespace

BENCHMARK_MAIN();
