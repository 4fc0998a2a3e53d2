#include "config/row_source.hpp"

namespace mpm::config {

Recording read_rows(RowSource& source) {
  Recording rec;
  rec.source = source.source();
  rec.names = source.names();
  std::vector<double> values, row;
  while (source.next(row)) values.insert(values.end(), row.begin(), row.end());
  const auto cols = static_cast<Eigen::Index>(rec.names.size());
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  rec.data = Eigen::Map<const RowMajor>(values.data(), static_cast<Eigen::Index>(values.size()) / cols, cols);
  return rec;
}

}  // namespace mpm::config
