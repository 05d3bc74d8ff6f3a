#pragma once
// The depth image MRPT keeps beside a rawlog (CObservation3DRangeScan::
// rangeImage_convertToExternalStorage: a gzip file holding the rows, the columns and the 16-bit
// values), read in one piece with libdeflate. MRPT inflates it through zlib's stream reader,
// which cost a tenth of the offline app's CPU on 7-Scenes; libdeflate inflates the same bytes
// in a fraction of that time.

namespace mrpt::obs {
class CObservation3DRangeScan;
}

namespace slamdunk {

/// Loads `obs`'s externally stored depth image when it is one MRPT wrote in its current format.
/// Returns false, and leaves `obs` untouched, for anything else (no external depth, already
/// loaded, a text file, the format of rawlogs older than MRPT's version 9, a damaged or missing
/// file): MRPT's own load() then reads it or reports the problem in its own words.
bool loadExternalDepthFile(const mrpt::obs::CObservation3DRangeScan& obs);

}  // namespace slamdunk
