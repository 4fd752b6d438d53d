#include "engine/memory_budget.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "engine/error.h"

namespace ballpit {

namespace {

// BALLPIT_MEMORY_LIMIT_MB as bytes, or 0 when unset or not a positive number.
double limit_from_environment() {
  const char* text = std::getenv("BALLPIT_MEMORY_LIMIT_MB");
  if (!text || !*text) return 0.0;
  char* end = nullptr;
  const double mb = std::strtod(text, &end);
  if (end == text || *end != '\0' || !(mb > 0.0))
    throw Error("BALLPIT_MEMORY_LIMIT_MB must be a positive number of MB, got '" + std::string(text) + "'");
  return mb * 1048576.0;
}

// "1.50 GiB" from a GiB up, "12 MiB" below.
std::string size_text(double bytes) {
  char text[48];
  if (bytes >= 1073741824.0)
    std::snprintf(text, sizeof text, "%.2f GiB", bytes / 1073741824.0);
  else
    std::snprintf(text, sizeof text, "%.0f MiB", bytes / 1048576.0);
  return text;
}

}  // namespace

double memory_budget_bytes() {
  const double limit = limit_from_environment();
  if (limit > 0.0) return limit;
  return static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
}

void refuse_if_too_big(std::size_t spheres, const std::string& flag) {
  const bool limited = limit_from_environment() > 0.0;
  const double budget = memory_budget_bytes();
  const double need = static_cast<double>(spheres) * kPeakBytesPerSphere;
  if (budget > 0 && need > budget) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "%s %zu needs about %s (%.0f bytes a sphere), more than %s %s; expected at most %.0f spheres",
                  flag.c_str(), spheres, size_text(need).c_str(), kPeakBytesPerSphere,
                  limited ? "the BALLPIT_MEMORY_LIMIT_MB budget of" : "this machine's", size_text(budget).c_str(),
                  budget / kPeakBytesPerSphere);
    throw Error(text);
  }
}

}  // namespace ballpit
