#include <slamdunk/optimization/LocalOptimizationReport.h>

#include <cstdio>

namespace slamdunk {

std::string LocalOptimizationReport::toString() const {
  const char* s = status == Status::Optimised           ? "optimised"
                  : status == Status::NothingToOptimise ? "nothing to optimise"
                                                        : "failed";
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "root %u: %s; %d free, %d fixed, %d edges, %d residuals (%d invalid, %d dropped), "
                "%d landmarks (%d observations); "
                "cost %.6g -> %.6g in %d it/%d rounds%s; max change %.4f m %.3f deg; %.2f ms",
                root, s, verticesOptimised, verticesFixed, edges, residuals, invalidMatches,
                droppedMatches, landmarks, observations, initialCost, finalCost, iterations, rounds,
                converged ? " (converged)" : "", maxTranslationChange, maxRotationChangeDeg,
                timeMs);
  return message.empty() ? buf : std::string(buf) + "; " + message;
}

}  // namespace slamdunk
