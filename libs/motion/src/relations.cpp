#include "mbot/motion/relations.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace mbot::motion {
namespace {

int64_t ToMicros(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

std::string Seconds(int64_t t_us) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(6) << t_us * 1e-6;
  return s.str();
}

// The pose at `t_us` when one lies within `tol_us`.
const Pose2D* Find(const std::map<int64_t, Pose2D>& poses, int64_t t_us, int64_t tol_us) {
  auto it = poses.lower_bound(t_us - tol_us);
  if (it == poses.end() || it->first > t_us + tol_us) return nullptr;
  // The closest of the candidates within the tolerance.
  const Pose2D* best = &it->second;
  int64_t best_d = std::llabs(it->first - t_us);
  for (++it; it != poses.end() && it->first <= t_us + tol_us; ++it) {
    if (std::llabs(it->first - t_us) < best_d) best = &it->second, best_d = std::llabs(it->first - t_us);
  }
  return best;
}

MeanStd Stats(const std::vector<double>& v) {
  MeanStd m;
  if (v.empty()) return m;
  for (double x : v) m.mean += x;
  m.mean /= v.size();
  for (double x : v) m.std += (x - m.mean) * (x - m.mean);
  m.std = std::sqrt(m.std / v.size());
  return m;
}

}  // namespace

std::vector<Relation> ReadRelations(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw RelationsError(path + ": cannot open the relations file");
  std::vector<Relation> out;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream s(line);
    double v[8];
    int k = 0;
    while (k < 8 && s >> v[k]) ++k;
    std::string rest;
    if (k < 8 || (s >> rest)) {
      const std::string shown =
          line.size() > 120 ? line.substr(0, 120) + "… (" + std::to_string(line.size()) + " bytes)" : line;
      throw RelationsError(path + ":" + std::to_string(n) +
                           ": a relation is eight numbers (t1 t2 x y z roll pitch yaw): '" + shown + "'");
    }
    for (double x : v) {
      if (!std::isfinite(x)) throw RelationsError(path + ":" + std::to_string(n) + ": a value is not finite");
    }
    if (v[0] < 0 || v[1] < 0 || v[0] > 4.1e9 || v[1] > 4.1e9) {
      throw RelationsError(path + ":" + std::to_string(n) + ": a timestamp is not seconds since 1970");
    }
    // A relation joins two poses of one building; its angles are radians. (t2 may come before t1:
    // Intel's hand-checked relations have six such, between scans whose arrival stamps jitter.)
    if (std::abs(v[2]) > 1e5 || std::abs(v[3]) > 1e5 || std::abs(v[4]) > 1e5)
      throw RelationsError(path + ":" + std::to_string(n) + ": a relative position beyond 100 km is not a relation");
    if (std::abs(v[5]) > 4 * M_PI || std::abs(v[6]) > 4 * M_PI || std::abs(v[7]) > 4 * M_PI)
      throw RelationsError(path + ":" + std::to_string(n) + ": an angle beyond 4 pi (radians) is not a relation");
    out.push_back({ToMicros(v[0]), ToMicros(v[1]), Pose2D{v[2], v[3], v[7]}, n});
  }
  return out;
}

RelationErrors ScoreRelations(const std::vector<Relation>& relations, const std::map<int64_t, Pose2D>& poses,
                              const std::string& source, int64_t tolerance_us) {
  RelationErrors r;
  r.relations = static_cast<int>(relations.size());
  if (poses.empty()) throw RelationsError(source + ": the trajectory to score has no pose");
  const int64_t first = poses.begin()->first - tolerance_us, last = poses.rbegin()->first + tolerance_us;
  std::vector<double> trans, rot, trans_sq, rot_sq;
  for (const Relation& rel : relations) {
    const bool in1 = rel.t1_us >= first && rel.t1_us <= last, in2 = rel.t2_us >= first && rel.t2_us <= last;
    if (!in1 && !in2) continue;  // the run did not reach this part of the log
    const Pose2D* a = Find(poses, rel.t1_us, tolerance_us);
    const Pose2D* b = Find(poses, rel.t2_us, tolerance_us);
    if (!a || !b) {
      const int64_t missing = !a && in1 ? rel.t1_us : rel.t2_us;
      if ((!a && in1) || (!b && in2)) {
        throw RelationsError(source + ":" + std::to_string(rel.line) + ": stamp " + Seconds(missing) +
                             " s matches no pose of the trajectory (within " + std::to_string(tolerance_us) + " us)");
      }
      continue;  // one end outside the run
    }
    const Pose2D e = rel.delta.Inverse().Compose(a->Inverse().Compose(*b));
    const double t = std::hypot(e.x, e.y), d = std::abs(WrapAngle(e.theta)) * 180.0 / M_PI;
    trans.push_back(t), rot.push_back(d), trans_sq.push_back(t * t), rot_sq.push_back(d * d);
    r.max_trans_m = std::max(r.max_trans_m, t), r.max_rot_deg = std::max(r.max_rot_deg, d);
  }
  if (trans.empty() && !relations.empty()) {
    throw RelationsError(source + ": no relation falls within the trajectory's time span (" + Seconds(first) + " … " +
                         Seconds(last) + " s; the first relation is at " + Seconds(relations[0].t1_us) + " s)");
  }
  r.scored = static_cast<int>(trans.size());
  r.trans_m = Stats(trans), r.rot_deg = Stats(rot), r.trans_sq_m2 = Stats(trans_sq), r.rot_sq_deg2 = Stats(rot_sq);
  return r;
}

}  // namespace mbot::motion
