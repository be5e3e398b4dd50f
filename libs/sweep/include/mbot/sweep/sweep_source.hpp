// Source type `sweep`: a sweep folder (one with the sweep.json that WriteSweep writes), the input of
// the merge stage (config/merge_sweep.ini). It yields no event: the stage reads the folder.
#pragma once

namespace mbot::sweep {

// Registers the type with libs/drivers' source registry. Idempotent.
void RegisterSweepSource();

}  // namespace mbot::sweep
