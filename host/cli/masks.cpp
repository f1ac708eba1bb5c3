#include "cli/masks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "tetcollapse/error.hpp"

namespace tc::cli {

std::vector<double> parse_numbers(const std::string& s, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string tok;
  while (std::getline(ss, tok, ',')) {
    char* end = nullptr;
    double x = std::strtod(tok.c_str(), &end);
    if (tok.empty() || *end != '\0' || !std::isfinite(x))
      throw CLI::ValidationError(what, "'" + tok + "' is not a number");
    v.push_back(x);
  }
  return v;
}

std::vector<uint8_t> region_mask(const Mesh& m, const std::string& spec) {
  auto colon = spec.find(':');
  std::string kind = spec.substr(0, colon);
  if (colon == std::string::npos || (kind != "box" && kind != "sphere"))
    throw CLI::ValidationError("--region", "expected box:X0,Y0,Z0,X1,Y1,Z1 or sphere:X,Y,Z,R");
  std::vector<double> v = parse_numbers(spec.substr(colon + 1), "--region");
  std::vector<uint8_t> mask(static_cast<size_t>(m.num_vertices()), 0);
  if (kind == "box") {
    if (v.size() != 6) throw CLI::ValidationError("--region", "box needs 6 numbers");
    for (int64_t i = 0; i < m.num_vertices(); ++i) {
      bool in = true;
      for (int k = 0; k < 3; ++k) {
        double x = m.points[3 * i + k];
        in = in && x >= std::min(v[k], v[k + 3]) && x <= std::max(v[k], v[k + 3]);
      }
      mask[i] = in;
    }
  } else {
    if (v.size() != 4 || v[3] < 0) throw CLI::ValidationError("--region", "sphere needs X,Y,Z,R with R >= 0");
    for (int64_t i = 0; i < m.num_vertices(); ++i) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) d2 += (m.points[3 * i + k] - v[k]) * (m.points[3 * i + k] - v[k]);
      mask[i] = d2 <= v[3] * v[3];
    }
  }
  return mask;
}

void require_labels(const Mesh& m) {
  if (m.tet_labels.empty()) throw InputError("--labels", "the mesh has no labels");
}

std::vector<uint8_t> label_mask(const Mesh& m, const std::string& spec) {
  require_labels(m);
  std::set<int32_t> wanted;
  for (double x : parse_numbers(spec, "--labels")) wanted.insert(static_cast<int32_t>(x));
  std::vector<uint8_t> mask(static_cast<size_t>(m.num_vertices()), 1);
  const auto& lab = m.tet_labels[0].values;
  for (int64_t t = 0; t < m.num_tets(); ++t)
    if (!wanted.count(lab[t]))
      for (int k = 0; k < 4; ++k) mask[m.tets[4 * t + k]] = 0;
  return mask;
}

void combine(std::vector<uint8_t>& mask, const std::vector<uint8_t>& more) {
  if (mask.empty()) {
    mask = more;
    return;
  }
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = mask[i] && more[i];
}

std::vector<uint8_t> region_and_label_mask(const Mesh& m, const std::string& region, const std::string& labels) {
  std::vector<uint8_t> mask;
  if (!region.empty()) combine(mask, region_mask(m, region));
  if (!labels.empty()) combine(mask, label_mask(m, labels));
  return mask;
}

void check_region_and_labels(const std::string& region, const std::string& labels) {
  if (!region.empty()) region_mask(Mesh{}, region);  // (no vertices: the spec alone)
  if (!labels.empty()) parse_numbers(labels, "--labels");
}

}  // namespace tc::cli
