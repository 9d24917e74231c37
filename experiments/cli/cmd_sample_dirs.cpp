// brdf-factor sample-dirs: importance-sampled light directions for one view
// direction (factor/sampling.h), one "wi.x wi.y wi.z pdf" line per sample;
// --chi2 instead tests the sampler against its own pdf (factor/sampling_chi2.h).
#include <iomanip>
#include <iostream>
#include <memory>
#include <random>
#include <stdexcept>

#include "brdfs/catalogue.h"
#include "experiments/cli/commands.h"
#include "experiments/common/cli_util.h"
#include "factor/sampling.h"
#include "factor/sampling_chi2.h"

namespace bf {

void add_cmd_sample_dirs(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "sample-dirs", "Importance-sample wi for a view direction: prints 'wi.x wi.y wi.z pdf' per sample");
  auto spec = std::make_shared<std::string>();
  auto wo = std::make_shared<std::string>();
  auto n = std::make_shared<long long>(10);
  auto seed = std::make_shared<unsigned long long>(1);
  auto method = std::make_shared<std::string>("auto");
  auto o = std::make_shared<SamplerOptions>();
  auto chi2 = std::make_shared<bool>(false);
  cmd->add_option("--brdf", *spec, "catalogue name[:k=v,...], measured file or factors.json")->required();
  cmd->add_option("--wo", *wo, "view direction x,y,z (local frame, normalized)")->required();
  cmd->add_option("-n", *n, "number of samples, 1..1e7")->capture_default_str();
  cmd->add_option("--seed", *seed, "seed of the uniform numbers (u1, u2)")
      ->check(non_negative_integer())
      ->capture_default_str();
  cmd->add_option("--method", *method, "auto | tabulated | cosine")->capture_default_str();
  cmd->add_option("--view-bins", o->view_bins, "theta_o bins of the table")->capture_default_str();
  cmd->add_option("--theta-bins", o->theta_bins, "theta_i cells of the table")->capture_default_str();
  cmd->add_option("--phi-bins", o->phi_bins, "phi_i cells of the table")->capture_default_str();
  cmd->add_flag("--chi2", *chi2, "run the chi-squared test of the sampler with n samples and print its result");
  cmd->callback([=] {
    if (*n < 1 || *n > 10000000)
      throw std::invalid_argument("sample-dirs: -n: expected an integer in 1..1e7, found " + std::to_string(*n));
    const Vec3 w = parse_direction(*wo, "--wo");
    if (!(w.z() > 0))
      throw std::invalid_argument("sample-dirs: --wo " + *wo + ": expected a direction above the horizon (z > 0)");
    const BrdfPtr b = Catalogue::global().make(*spec);
    std::shared_ptr<const BrdfSampler> s;
    if (*method == "cosine") {
      s = cosine_sampler();
    } else if (*method == "auto" || *method == "tabulated") {
      SamplerOptions so = *o;
      so.method = *method;
      try {
        s = make_sampler(*b, so);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("sample-dirs: ") + e.what());
      }
    } else {
      throw std::invalid_argument("sample-dirs: --method: expected auto, tabulated or cosine, found " + *method);
    }
    std::cout << std::setprecision(9);
    if (*chi2) {
      Chi2Options co;
      co.samples = static_cast<size_t>(*n), co.seed = *seed;
      const Chi2Result r = chi2_test(*s, w, co);
      std::cout << "method " << s->method() << " storage_floats " << s->storage_floats() << " chi2 " << r.chi2
                << " dof " << r.dof << " p " << r.p << " valid " << r.valid
                << (r.problem.empty() ? "" : " problem: " + r.problem) << "\n";
      return;
    }
    std::mt19937_64 rng(*seed);
    auto uni = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    for (long long k = 0; k < *n; ++k) {
      const double u1 = uni(), u2 = uni();
      const DirectionSample d = s->sample(w, u1, u2);
      std::cout << d.wi.x() << " " << d.wi.y() << " " << d.wi.z() << " " << d.pdf << "\n";
    }
  });
}

}  // namespace bf
