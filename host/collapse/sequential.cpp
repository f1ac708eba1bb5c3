// The sequential CPU method (CollapseOptions::Sequential): see collapse/sequential_run.hpp for
// the iteration and collapse/sequential_mesh.hpp for the dynamic mesh and its checks.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "collapse/sequential_run.hpp"
#include "collapse/stages.hpp"  // collapse_detail::Reason
#include "collapse/upload.hpp"  // collapse_detail::remap_elements
#include "collapse_predicate.h"
#include "tetcollapse/collapse.hpp"

namespace tc {

namespace sequential_detail {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Options first (std::invalid_argument), as collapse() checks them before touching the mesh.
SeqParams checked_params(const Mesh& mesh, const CollapseOptions& o) {
  if (o.max_iterations < 0) throw std::invalid_argument("max_iterations must be >= 0");
  if (o.has_user_functions())
    throw std::invalid_argument(
        "the sequential method cannot evaluate a user cost, placement or predicate (cost_cl_source, also behind "
        "--sizing-field, placement_cl_source, predicate_cl_source): they are OpenCL C, compiled for a device; use "
        "the parallel method");
  if (!(o.target_length > 0) && !(o.target_factor > 0))
    throw std::invalid_argument("target_factor must be > 0 when target_length is not given");
  if (!o.vertex_mask.empty() && o.vertex_mask.size() != size_t(mesh.num_vertices()))
    throw std::invalid_argument("vertex_mask has " + std::to_string(o.vertex_mask.size()) + " entries for " +
                                std::to_string(mesh.num_vertices()) + " vertices");
  collapse_detail::check_boundary_error_options(o);
  collapse_detail::check_field_points_options(o);
  if (!(o.max_field_error >= 0) || std::isinf(o.max_field_error))
    throw std::invalid_argument("max_field_error must be finite and >= 0");
  if (o.field_difference_cost && (!(o.target_length > 0) || mesh.vertex_fields.empty()))
    throw std::invalid_argument("field_difference_cost needs an explicit target_length > 0 and a vertex field");
  SeqParams p = seq_params_from(o);
  p.eps_v = volume_threshold(mesh, o);  // as collapse() computes it
  // With a bound, a smoothly curved face's vertices are face vertices: the bound decides.
  if (o.bounds_boundary_error()) p.eps_f = 2;
  return p;
}

// A collapse the measured bound makes (one the carried bound refuses) leaves the tets it
// reshapes at least this mean ratio (or what they had): it reaches S where the carried bound
// stopped, and the improvement that follows has little of the bound left to move S there
// (bench/README.md: 0 against 0.2 and 0.3 on six shared meshes).
constexpr double kMeasuredMinQuality = 0.2;

// The greedy mode's set of queued edges is keyed by a << 32 | b.
uint64_t key(int32_t a, int32_t b) { return uint64_t(uint32_t(a)) << 32 | uint32_t(b); }

// Queue order: (cost, a, b) ascending, i.e. (cost, edge index); a heap comparator is "after".
bool after(double ca, int32_t aa, int32_t ab, double cb, int32_t ba, int32_t bb) {
  if (ca != cb) return ca > cb;
  return aa != ba ? aa > ba : ab > bb;
}

}  // namespace

SeqParams seq_params_from(const CollapseOptions& o) { return collapse_detail::check_params_from(o); }

SequentialRun::SequentialRun(Mesh& mesh, const CollapseOptions& options, const TailSeed* seed)
    : mesh_(mesh),
      o_(options),
      t_start_(std::chrono::steady_clock::now()),
      params_(checked_params(mesh, options)),
      sm_(mesh, params_, seed ? &seed->vflags : nullptr, seed ? &seed->vclass : nullptr,
          seed && !seed->tet_nbr.empty() ? &seed->tet_nbr : nullptr) {
  report_.device = "cpu-sequential";
  report_.vertices_in = mesh.num_vertices();
  report_.tets_in = mesh.num_tets();
  report_.eps_v = params_.eps_v;
  mask_ = options.vertex_mask;
  bound_ = boundary_error_bound(mesh, options);
  if (bound_ > 0) eps_ = collapse_detail::initial_boundary_error(mesh, options);
  if (bound_ > 0 && collapse_detail::measures_boundary_error(options)) {
    reference_triangles_ = options.boundary_reference;
    if (!reference_triangles_) {
      auto own = std::make_shared<std::vector<double>>();
      sm_.s_triangles(*own);
      reference_triangles_ = std::move(own);
    }
    reference_ = std::make_unique<surface_distance::ReferenceSurface>(*reference_triangles_);
    reach_ = bound_;
    for (double e : eps_) reach_ = std::max(reach_, e);
  }
  if (options.max_field_error > 0) {
    field_ = std::make_unique<FieldBound>(mesh, options, sm_);
    report_.field_error_bound = field_->bound();
  }
  if (!mesh.tris.empty() || !mesh.edges.empty()) {
    origin_.resize(size_t(mesh.num_vertices()));
    for (size_t i = 0; i < origin_.size(); ++i) origin_[i] = int32_t(i);
  }
  touched_.assign(size_t(sm_.num_vertices()), 0);  // 0: touched "in the iteration before the first"
  if (seed && o_.tuning.reuse_across_iterations) {
    if (seed->touched.size() != touched_.size())
      throw std::invalid_argument("SequentialRun: the seed's touched flags need one entry per vertex");
    // untouched: a value no iteration's prev or cur (it_, it_ + 1) takes
    for (size_t v = 0; v < touched_.size(); ++v) touched_[v] = seed->touched[v] ? 0u : 0xffffffffu;
  }
  if (seed) {
    seed_edges_ = seed->edges;
    const int32_t nv = sm_.num_vertices();
    bool ok = seed_edges_.size() % 2 == 0;
    for (size_t i = 0; ok && i < seed_edges_.size(); i += 2)
      ok = 0 <= seed_edges_[i] && seed_edges_[i] < seed_edges_[i + 1] && seed_edges_[i + 1] < nv;
    if (!ok) throw std::invalid_argument("SequentialRun: the seed's edges need pairs a < b of vertices of the mesh");
  }
  target_ = options.target_length;
  if (options.harmonic_cost) {
    if (!o_.placement_cl_source.empty()) throw std::invalid_argument("harmonic_cost has its own placement");
    sm_.set_free_placement([this](int32_t a, int32_t b, geo::tc_d3* p) {
      harmonic_place(a, b, p);
      return true;
    });
  }
}

double SequentialRun::harmonic_place(int32_t a, int32_t b, geo::tc_d3* place) {
  if (last_place_.a == a && last_place_.b == b && last_place_.collapses == collapses_) {
    *place = last_place_.place;
    return last_place_.sum;
  }
  const geo::tc_d3 pa = geo::tc_point(mesh_.points.data(), a), pb = geo::tc_point(mesh_.points.data(), b);
  auto at = [&](double t) { return pa + (pb - pa) * t; };
  sm_.harmonic_terms(a, b, terms_);
  auto sum = [&](double t) { return SeqMesh::harmonic_at(terms_, t); };
  // samples, then a golden-section search in the best one's bracket (the sum need not be
  // convex along the edge; deterministic, so the checks and the collapse see the same place)
  constexpr int kSamples = 8;
  int best = 0;
  double best_sum = INFINITY;
  for (int i = 0; i <= kSamples; ++i) {
    const double s = sum(double(i) / kSamples);
    if (s < best_sum) best_sum = s, best = i;
  }
  double lo = double(std::max(best - 1, 0)) / kSamples, hi = double(std::min(best + 1, kSamples)) / kSamples;
  const double g = (std::sqrt(5.0) - 1) / 2;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = sum(x1), f2 = sum(x2);
  for (int it = 0; it < 16; ++it) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = sum(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = sum(x2);
    }
  }
  double t = double(best) / kSamples;
  if (std::min(f1, f2) < best_sum) best_sum = std::min(f1, f2), t = f1 < f2 ? x1 : x2;
  *place = at(t);
  last_place_ = {a, b, collapses_, *place, best_sum};
  return best_sum;
}

double SequentialRun::harmonic_cost(int32_t a, int32_t b) {
  if (!selected(a, b)) return INFINITY;
  uint8_t fe = 0;
  const int dir = sm_.predicate(a, b, fe);
  if (dir < 0) return INFINITY;
  geo::tc_d3 p;
  double after;
  if (dir & TCC_DIR_MIDPOINT) {
    after = harmonic_place(a, b, &p);
  } else {
    p = geo::tc_point(mesh_.points.data(), (dir & TCC_DIR_REMOVE_V1) ? a : b);
    after = sm_.harmonic_sum(a, b, &p);
  }
  const double gain = sm_.harmonic_sum(a, b, nullptr) - after;
  if (!(gain > 0)) return INFINITY;
  // and, as every operation of the improvement, only if the worst tet of the region (by its
  // smallest dihedral angle's sine) is no worse after (asked last: the sines cost more)
  return sm_.worst_sine(a, b, &p) >= sm_.worst_sine(a, b, nullptr) ? -gain : INFINITY;
}

bool SequentialRun::step() {
  using namespace collapse_detail;
  if (done_ || it_ >= o_.max_iterations || sm_.alive_tets() == 0) {
    done_ = true;
    return false;
  }
  IterationStats s;
  s.iteration = it_;
  s.vertices = sm_.alive_vertices();
  s.tets = sm_.alive_tets();
  const auto t0 = std::chrono::steady_clock::now();

  // 1. edges and costs
  edges_.clear();
  if (greedy_ && it_ > 0) {
    // Greedy, after an iteration whose surface guard refused some edges (else the run is done):
    // every other marked edge was tested after the last change of its star and refused, and
    // the guard refuses nothing else, so those edges are the candidates (their end points
    // renumbered by the compaction; an edge gone since is dropped by is_edge).
    for (size_t i = 0; i + 1 < refused_.size(); i += 2) {
      const int32_t a = std::min(refused_[i], refused_[i + 1]), b = std::max(refused_[i], refused_[i + 1]);
      if (sm_.is_edge(a, b)) edges_.push_back({cost(a, b), a, b, 0});
    }
    std::sort(edges_.begin(), edges_.end(), [](const QueueEntry& x, const QueueEntry& y) {
      return x.a != y.a ? x.a < y.a : x.b < y.b;
    });
    edges_.erase(std::unique(edges_.begin(), edges_.end(),
                             [](const QueueEntry& x, const QueueEntry& y) { return x.a == y.a && x.b == y.b; }),
                 edges_.end());
  } else if (!seed_edges_.empty()) {  // the device's, of this mesh (TailSeed::edges)
    edges_.reserve(seed_edges_.size() / 2);
    for (size_t i = 0; i + 1 < seed_edges_.size(); i += 2) {
      const int32_t a = seed_edges_[i], b = seed_edges_[i + 1];
      edges_.push_back({cost(a, b), a, b, 0});
    }
    seed_edges_ = {};
  } else {
    const int32_t nv = sm_.num_vertices();
    // with a mask that needs both ends, only the edges between selected vertices can be marked:
    // only those are listed
    const bool both_selected = !mask_.empty() && !o_.mask_either;
    for (int32_t v = 0; v < nv; ++v) {
      if (both_selected && !mask_[v]) continue;
      sm_.neighbours(v, nb_, true);
      for (int32_t u : nb_)
        if (!both_selected || mask_[u]) edges_.push_back({cost(v, u), v, u, 0});
    }
  }
  s.edges = int64_t(edges_.size());
  const double t1 = seconds_since(t0);
  if (it_ == 0 && o_.harmonic_cost) target_ = 0;  // every edge whose collapse lowers the sum
  if (it_ == 0 && !o_.harmonic_cost && !(target_ > 0 && std::isfinite(target_))) {
    // the median edge length of the input (the lower median, as tc::median_edge_length)
    std::vector<double> len(edges_.size());
    for (size_t i = 0; i < edges_.size(); ++i) len[i] = edges_[i].cost;
    if (!len.empty()) {
      const size_t m = (len.size() - 1) / 2;
      std::nth_element(len.begin(), len.begin() + m, len.end());
      report_.median_edge_length = len[m];
    }
    // with the field bound and no target, every edge is a candidate: the bound decides
    if (!(target_ > 0)) target_ = field_ ? INFINITY : o_.target_factor * report_.median_edge_length;
  }
  if (it_ == 0) {
    double h = std::isfinite(target_) && target_ > 0 ? target_ : report_.median_edge_length;
    sm_.build_guard(h > 0 ? h : 1.0);  // (h: the cell size when there is no S face)
  }
  // marking, Q, link and volume; the admissible edges into the queue
  const bool reuse = o_.tuning.reuse_across_iterations;
  const uint32_t prev = uint32_t(it_);  // touched_ value of the previous iteration (0: the input)
  auto marked = [&](int32_t a, int32_t b, double c) { return selected(a, b) && c < target_; };
  heap_.clear();
  for (const QueueEntry& e : edges_) {
    if (!marked(e.a, e.b, e.cost)) continue;
    ++s.marked;
    uint8_t fe = 0;
    const int dir = predicate(e.a, e.b, fe);
    if (dir < 0) continue;
    ++s.candidates;
    if (reuse && touched_[e.a] != prev && touched_[e.b] != prev) continue;  // refused then, refused now
    ++s.tested;
    if (!sm_.admissible(e.a, e.b, fe, dir)) continue;
    heap_.push_back({e.cost, e.a, e.b, uint8_t(dir)});
    if (greedy_) queued_.insert(key(e.a, e.b));
  }
  s.selected = int64_t(heap_.size());
  auto later = [](const QueueEntry& x, const QueueEntry& y) { return after(x.cost, x.a, x.b, y.cost, y.a, y.b); };
  std::make_heap(heap_.begin(), heap_.end(), later);
  const double t2 = seconds_since(t0);

  // 2. pop, check again where an earlier collapse changed the star, collapse
  const uint32_t cur = uint32_t(it_) + 1;
  int64_t guard_refusals = 0;
  refused_.clear();
  while (!heap_.empty()) {
    std::pop_heap(heap_.begin(), heap_.end(), later);
    const QueueEntry e = heap_.back();
    heap_.pop_back();
    if (greedy_) queued_.erase(key(e.a, e.b));
    if (!sm_.alive(e.a) || !sm_.alive(e.b)) continue;
    uint8_t dir = e.dir;
    const bool invalidated = touched_[e.a] == cur || touched_[e.b] == cur;
    // the paper's reading: next iteration (not in greedy mode, whose stop rule and listing of
    // the guard's refusals rely on every invalidated edge being tested again)
    if (invalidated && o_.sequential_skip_invalidated && !greedy_) continue;
    if (!reuse || invalidated) {
      if (!sm_.is_edge(e.a, e.b)) continue;
      const double c = cost(e.a, e.b);
      if (!marked(e.a, e.b, c)) continue;
      if (c != e.cost) {  // an end point moved: back into the queue at its new place
        if (greedy_) queued_.insert(key(e.a, e.b));
        heap_.push_back({c, e.a, e.b, 0});
        std::push_heap(heap_.begin(), heap_.end(), later);
        continue;
      }
      uint8_t fe = 0;
      const int d = predicate(e.a, e.b, fe);
      if (d < 0 || !sm_.admissible(e.a, e.b, fe, d)) continue;
      dir = uint8_t(d);
    }
    double base = 0, change = 0;  // (the bound's, for dir)
    const bool merge = merges_feature(e.a, e.b);  // (measured alone, onto its end point)
    if (bound_ > 0 && !merge) dir = sm_.closest_placement(e.a, e.b, dir, eps_, &base, &change);
    const auto guard_refuses = [&] {
      if (sm_.guard_ok(e.a, e.b, dir)) return false;
      // refused by the surface guard, which looks beyond the star: its end points count as
      // touched, so the edge is tested again next iteration (S nearby may have moved away)
      touched_[e.a] = touched_[e.b] = cur;
      ++guard_refusals;
      ++s.refused_by_guard;
      if (greedy_) refused_.insert(refused_.end(), {e.a, e.b});
      return true;
    };
    // Greedy (the host tail), the bounds come first: they refuse most of what is popped there,
    // the guard hardly anything they let through, and an edge both refuse is tested again only
    // once its star changes either way. Else the guard first: its refusal defers the edges at
    // its end points (sequential_skip_invalidated).
    if (!greedy_ && guard_refuses()) continue;
    double eps_after = 0;
    bool measured = false;
    if (bound_ > 0) {
      // the carried bound, else the change measured against the reference
      const bool carried = !merge && base + change <= bound_;
      measured = !carried && reference_ && sm_.keeps_shape(e.a, e.b, dir, kMeasuredMinQuality) &&
                 measured_ok(e.a, e.b, dir);
      if (!carried && !measured) {
        ++s.refused_by_bound;
        continue;  // (the verdict depends on the star alone: no retest unless it changes)
      }
      if (change > 0) eps_after = base + change;
    }
    if (field_ && !field_->admits(sm_, mesh_, e.a, e.b, dir)) {
      ++s.refused_by_bound;
      continue;  // (as the boundary bound: the verdict changes only with the star)
    }
    if (greedy_ && guard_refuses()) continue;
    const int32_t survivor = sm_.collapse(e.a, e.b, dir);
    ++collapses_;
    if (field_) field_->apply(mesh_, survivor);
    if (measured) {
      // The new S triangles and those around them now stand for the reference near them, up
      // to the whole bound: the carried bound never builds on them (a change of them it
      // measures adds to the whole bound).
      eps_[size_t(survivor)] = bound_;
      for (int32_t v : corners_) eps_[size_t(v)] = std::max(eps_[size_t(v)], bound_);
    } else if (eps_after > 0) {
      eps_[size_t(survivor)] = std::max(eps_[size_t(survivor)], eps_after);
    }
    ++s.collapsed;
    for (int32_t u : sm_.touched()) touched_[u] = cur;
    if (greedy_) {
      // the marked edges whose star changed, into the queue now (tested when popped: their end
      // points are touched) instead of waiting for the next iteration
      ++greedy_stamp_;
      if (greedy_mark_.size() < size_t(sm_.num_vertices())) greedy_mark_.resize(size_t(sm_.num_vertices()), 0);
      for (int32_t u : sm_.touched()) greedy_mark_[u] = greedy_stamp_;
      for (int32_t u : sm_.touched()) {  // neighbours() and length() leave touched() as it is
        if (!sm_.alive(u)) continue;
        sm_.neighbours(u, nb_);
        for (int32_t w : nb_) {
          // each edge once per collapse: from its lower end point when both are touched
          if (w < u && greedy_mark_[w] == greedy_stamp_) continue;
          const int32_t a = std::min(u, w), b = std::max(u, w);
          const double c = cost(a, b);
          if (!marked(a, b, c)) continue;
          if (!queued_.insert(key(a, b))) continue;  // already queued (popped: tested again)
          heap_.push_back({c, a, b, 0});
          std::push_heap(heap_.begin(), heap_.end(), later);
        }
      }
    }
  }

  // 3. compaction
  if (s.collapsed > 0) {
    // a refused edge with an end point removed since is gone: the edges at the survivor were
    // tested after that collapse
    size_t kept_refused = 0;
    for (size_t i = 0; i + 1 < refused_.size(); i += 2)
      if (sm_.alive(refused_[i]) && sm_.alive(refused_[i + 1])) {
        refused_[kept_refused++] = refused_[i];
        refused_[kept_refused++] = refused_[i + 1];
      }
    refused_.resize(kept_refused);
    if (field_) {
      tmap_.assign(size_t(sm_.num_tets()), -1);
      for (int32_t t = 0, m = 0; t < sm_.num_tets(); ++t)
        if (sm_.tet_alive(t)) tmap_[size_t(t)] = m++;
    }
    sm_.compact(vmap_, kept_);
    last_place_ = {};  // (renumbered)
    if (field_) field_->compact(tmap_);
    // per-vertex data of the survivors; origin composed with the vertex map
    for (size_t i = 0; i < kept_.size(); ++i) touched_[i] = touched_[kept_[i]];
    touched_.resize(kept_.size());
    if (!mask_.empty()) {
      for (size_t i = 0; i < kept_.size(); ++i) mask_[i] = mask_[kept_[i]];
      mask_.resize(kept_.size());
    }
    if (!eps_.empty()) {
      for (size_t i = 0; i < kept_.size(); ++i) eps_[i] = eps_[kept_[i]];
      eps_.resize(kept_.size());
    }
    for (int32_t& x : origin_) x = vmap_[x];
    if (!source_.empty()) {
      for (size_t i = 0; i < kept_.size(); ++i) source_[i] = source_[kept_[i]];
      source_.resize(kept_.size());
    }
    for (int32_t& x : refused_) x = vmap_[x];  // their end points are alive (above)
  }
  const double t4 = seconds_since(t0);
  s.seconds_connectivity = t1;
  s.seconds_cost = 0;  // the lengths come with the edge list
  s.seconds_select = t2 - t1;
  s.seconds_collapse = t4 - t2;
  s.seconds_total = t4;
  s.vertices_after = sm_.alive_vertices();
  s.tets_after = sm_.alive_tets();
  report_.iterations.push_back(s);
  if (o_.progress) o_.progress(s);
  ++it_;
  if (s.collapsed < std::max<int64_t>(o_.eps_c, 1)) done_ = true;
  // Greedy: every marked edge was tested after the last change of its star, so nothing is
  // admissible now, unless the surface guard, which looks beyond the star, refused one (S
  // nearby may have moved since): only then another iteration.
  if (greedy_ && guard_refusals == 0) done_ = true;
  return !done_;
}

void SequentialRun::seed_boundary_error(std::vector<double> eps) {
  if (it_ > 0) throw std::logic_error("SequentialRun::seed_boundary_error: after the first step");
  if (!(bound_ > 0)) throw std::logic_error("SequentialRun::seed_boundary_error: no bound");
  if (eps.size() != eps_.size())
    throw std::invalid_argument("seed_boundary_error: " + std::to_string(eps.size()) + " values for " +
                                std::to_string(eps_.size()) + " vertices");
  eps_ = std::move(eps);
  // a run that goes on from an earlier one: its own S is no reference
  if (!o_.boundary_reference) {
    reference_.reset();
    reference_triangles_.reset();
  }
  if (reference_)
    for (double e : eps_) reach_ = std::max(reach_, e);
}

int SequentialRun::predicate(int32_t a, int32_t b, uint8_t& fe) {
  const int dir = sm_.predicate(a, b, fe);
  if (dir >= 0 || !merges_feature(a, b, &fe)) return dir;
  // onto the end of the higher class (the lower index at a tie), else the other, else the
  // midpoint: the first the volume and quality tests admit
  const int first = sm_.vclass(a) >= sm_.vclass(b) ? int(TCC_DIR_REMOVE_V1) : 0;
  for (int d : {first, first ^ int(TCC_DIR_REMOVE_V1), int(TCC_DIR_MIDPOINT | TCC_DIR_REMOVE_V1)})
    if (sm_.link_and_volume(a, b, fe, d) == collapse_detail::kOk) return d;
  return first;
}

bool SequentialRun::merges_feature(int32_t a, int32_t b, const uint8_t* refused_fe) {
  if (!reference_ || !o_.tuning.merge_features_within_bound) return false;
  // an edge of the boundary alone: an interface's details are a material's, which stay
  const uint8_t fa = sm_.vflags(a), fb = sm_.vflags(b);
  if (!(fa & fb & TCC_BOUNDARY) || ((fa | fb) & TCC_INTERFACE) || !(sm_.length(a, b) <= bound_)) return false;
  uint8_t fe = 0;
  if (refused_fe) fe = *refused_fe;
  else if (sm_.predicate(a, b, fe) >= 0) return false;
  return (fe & TCC_BOUNDARY) && !(fe & TCC_INTERFACE);
}

bool SequentialRun::measured_ok(int32_t a, int32_t b, uint8_t dir) {
  sm_.collapse_fans(a, b, dir, olds_, news_, around_, corners_);
  return reference_->change_ok(olds_, news_, around_, bound_, reach_);
}

void SequentialRun::keep_origin() {
  if (it_ > 0) throw std::logic_error("SequentialRun::keep_origin: after the first step");
  const size_t n = size_t(mesh_.num_vertices());
  origin_.resize(n);
  source_.resize(n);
  for (size_t i = 0; i < n; ++i) origin_[i] = source_[i] = int32_t(i);
}

CollapseReport SequentialRun::finish() {
  if (!origin_.empty()) {
    collapse_detail::remap_elements(mesh_.tris, mesh_.tri_tags, 3, origin_);
    collapse_detail::remap_elements(mesh_.edges, mesh_.edge_tags, 2, origin_);
  }
  report_.target_length = target_;
  report_.boundary_error_bound = bound_;
  for (size_t v = 0; v < eps_.size(); ++v)
    if (sm_.alive(int32_t(v))) report_.boundary_error = std::max(report_.boundary_error, eps_[v]);
  if (bound_ > 0) report_.vertex_boundary_error = eps_;
  report_.boundary_reference = reference_triangles_;
  if (field_) report_.field_error = field_->max_error(sm_, mesh_);
  report_.vertices_out = mesh_.num_vertices();
  report_.tets_out = mesh_.num_tets();
  report_.seconds_total = seconds_since(t_start_);
  return report_;
}

}  // namespace sequential_detail

CollapseReport collapse_sequential(Mesh& mesh, const CollapseOptions& options) {
  sequential_detail::SequentialRun run(mesh, options);
  while (run.step()) {
  }
  return run.finish();
}

}  // namespace tc
