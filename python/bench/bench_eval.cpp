// The C++ side of python/bench/bench_eval.py: the factor-and-evaluate round trip
// (McCool fit on the res^4 grid, then f(wi, wo) at N direction pairs) timed in
// C++, to compare with the same round trip through the Python module.
//   bench-eval-cpp BRDF GRID TEXTURE DIRS.bin OUT.bin
// DIRS.bin: N x 6 float64 (wi, wo per row, as numpy's tofile writes them);
// OUT.bin: N x 3 float64 values. Prints one JSON line:
// {"fit_seconds", "eval_seconds", "seconds", "n"} (file I/O excluded).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "brdfs/catalogue.h"
#include "brdfs/sampleset.h"
#include "factor/homomorphic_fit.h"

int main(int argc, char** argv) {
  using Clock = std::chrono::steady_clock;
  try {
    if (argc != 6) throw std::invalid_argument("usage: bench-eval-cpp BRDF GRID TEXTURE DIRS.bin OUT.bin");
    const bf::BrdfPtr b = bf::Catalogue::builtin().make(argv[1]);
    const int grid = std::stoi(argv[2]), texture = std::stoi(argv[3]);
    std::ifstream in(argv[4], std::ios::binary | std::ios::ate);
    if (!in) throw std::runtime_error(std::string(argv[4]) + ": cannot open");
    const size_t bytes = static_cast<size_t>(in.tellg());
    if (bytes % (6 * sizeof(double))) throw std::runtime_error(std::string(argv[4]) + ": size is not a multiple of 48 bytes");
    const size_t n = bytes / (6 * sizeof(double));
    std::vector<double> dirs(6 * n), out(3 * n);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(dirs.data()), static_cast<std::streamsize>(bytes));

    const auto t0 = Clock::now();
    const bf::SampleSet s = bf::sample_grid(*b, grid);
    const bf::FitData data(s, 1e-5);
    const auto f = bf::fit_homomorphic(data, bf::mccool_terms(texture), bf::FitOptions{}, "mccool");
    const auto t1 = Clock::now();
    // The same loop as the module's Brdf.eval: normalize (unless unit to 1e-14), evaluate.
    for (size_t k = 0; k < n; ++k) {
      const bf::Vec3 wi(dirs[6 * k], dirs[6 * k + 1], dirs[6 * k + 2]);
      const bf::Vec3 wo(dirs[6 * k + 3], dirs[6 * k + 4], dirs[6 * k + 5]);
      const double li = wi.norm(), lo = wo.norm();
      const bf::Rgb v = f->eval(std::abs(li - 1.0) <= 1e-14 ? wi : bf::Vec3(wi / li),
                                std::abs(lo - 1.0) <= 1e-14 ? wo : bf::Vec3(wo / lo));
      out[3 * k] = v[0];
      out[3 * k + 1] = v[1];
      out[3 * k + 2] = v[2];
    }
    const auto t2 = Clock::now();
    std::ofstream o(argv[5], std::ios::binary);
    o.write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size() * sizeof(double)));
    if (!o) throw std::runtime_error(std::string(argv[5]) + ": write failed");
    const auto sec = [](Clock::time_point a, Clock::time_point c) { return std::chrono::duration<double>(c - a).count(); };
    std::printf("{\"fit_seconds\": %.6f, \"eval_seconds\": %.6f, \"seconds\": %.6f, \"n\": %zu}\n", sec(t0, t1),
                sec(t1, t2), sec(t0, t2), n);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bench-eval-cpp: " << e.what() << "\n";
    return 2;
  }
}
