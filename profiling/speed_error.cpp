// The speed-against-error sweep (issue 5): runs every case of profiling/cases.h at every solver
// setting of the sweep and prints one JSON line per point on stdout (progress on stderr).
// scripts/profile_speed_error.sh turns the lines into the CSV, the Pareto plot and the table.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <set>
#include <sstream>
#include <string>

#include "engine/error.h"
#include "profiling/cases.h"

using namespace ballpit::profiling;

namespace {

std::set<std::string> split(const std::string& s) {
  std::set<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.insert(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Speed against error: sweep solver settings over the reference cases"};
  std::string cases = "bounce,cradle,stack,gas,crowd,pour,character,pour-big";
  std::string points;
  CaseOptions options;
  std::size_t big_spheres = 100000;
  bool list = false;
  int small_repeats = 5;
  app.add_option("--cases", cases, "Cases to run, comma-separated: bounce,cradle,stack,gas,crowd,pour,character,pour-big")->capture_default_str();
  app.add_option("--points", points, "Only these sweep points (labels, comma-separated; default: all)");
  app.add_option("--threads", options.threads, "Threads for the gas, the crowd, the pours and the character (results do not depend on it)")->capture_default_str()->check(CLI::Range(1, 256));
  app.add_option("--small-threads", options.small_threads, "Threads for bounce, cradle and stack (1 to 50 spheres)")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  app.add_option("--pour-spheres", options.pour_spheres, "N of the swept pour")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--character-spheres", options.character_spheres, "N of the pit-character case")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--big-pour-spheres", big_spheres, "N of the big pour (pour-big: a few points only)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--small-repeats", small_repeats, "Runs of bounce, cradle and stack per point; the cheapest is kept")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app.add_flag("--list", list, "List the sweep points and exit");
  CLI11_PARSE(app, argc, argv);

  if (list) {
    for (const SolverPoint& p : sweep_points()) std::cout << p.to_json().dump() << "\n";
    return 0;
  }
  const std::set<std::string> want_cases = split(cases);
  // Labels may hold commas themselves ("dt=1/30,substeps=16"), so the list is matched against
  // the labels, longest first: each takes its place out of the list, and what no label takes
  // is an error.
  std::set<std::string> want_points;
  if (!points.empty()) {
    std::vector<std::string> labels;
    for (const SolverPoint& p : sweep_points()) labels.push_back(p.label);
    std::stable_sort(labels.begin(), labels.end(), [](const std::string& a, const std::string& b) { return a.size() > b.size(); });
    std::string rest = "," + points + ",";
    for (const std::string& label : labels)
      for (std::size_t at; (at = rest.find("," + label + ",")) != std::string::npos;) {
        rest.erase(at, label.size() + 1);
        want_points.insert(label);
      }
    if (rest != ",") {
      std::cerr << "speed_error: --points: no sweep point named '" << rest.substr(1, rest.size() - 2)
                << "' (see --list)\n";
      return 2;
    }
  }
  auto wanted = [&](const SolverPoint& p) { return points.empty() || want_points.count(p.label) > 0; };
  using Runner = nlohmann::ordered_json (*)(const SolverPoint&, const CaseOptions&);
  const std::pair<const char*, Runner> runners[] = {
      {"bounce", run_bounce}, {"cradle", run_cradle}, {"stack", run_stack},
      {"gas", run_gas},       {"crowd", run_crowd},   {"pour", run_pour},
      {"character", run_character}};

  try {
    for (const auto& [name, runner] : runners) {
      if (!want_cases.count(name)) continue;
      // The small cases take milliseconds: run them several times and keep the cheapest run,
      // the one the rest of the machine disturbed least (every run computes the same state).
      const std::string case_name = name;
      const bool small = case_name == "bounce" || case_name == "cradle" || case_name == "stack";
      for (const SolverPoint& p : sweep_points()) {
        if (!wanted(p)) continue;
        auto t0 = std::chrono::steady_clock::now();
        nlohmann::ordered_json j = runner(p, options);
        for (int k = 1; small && k < small_repeats; ++k) {
          nlohmann::ordered_json again = runner(p, options);
          if (again["state_hash"] != j["state_hash"]) j["nondeterministic"] = true;
          if (again["cost_ms_per_sim_s"].get<double>() < j["cost_ms_per_sim_s"].get<double>()) {
            again["nondeterministic"] = j.value("nondeterministic", false);
            j = again;
          }
        }
        if (small) j["repeats"] = small_repeats;
        std::cout << j.dump() << std::endl;
        std::fprintf(stderr, "[speed_error] %-8s %-24s error %.4g  cost %.3g ms/s  (%.1f s)\n", name, p.label.c_str(),
                     j["error"].get<double>(), j["cost_ms_per_sim_s"].get<double>(),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
    }
    if (want_cases.count("pour-big")) {
      CaseOptions big = options;
      big.pour_spheres = big_spheres;
      for (const SolverPoint& p : big_pour_points()) {
        if (!wanted(p)) continue;
        auto t0 = std::chrono::steady_clock::now();
        nlohmann::ordered_json j = run_pour(p, big);
        std::cout << j.dump() << std::endl;
        std::fprintf(stderr, "[speed_error] pour-big %-24s error %.4g  cost %.3g ms/s  (%.1f s)\n", p.label.c_str(),
                     j["error"].get<double>(), j["cost_ms_per_sim_s"].get<double>(),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
    }
  } catch (const ballpit::Error& e) {
    std::fprintf(stderr, "speed_error: %s\n", e.what());
    return 2;
  }
  return 0;
}
