// The settings tables as a Markdown table (key, default, allowed values,
// meaning): the table of deploy/README.md, generated from the rows so it
// cannot drift (`mpmd --settings-table` prints it; a test compares).
#pragma once

#include <string>

namespace mpm::config {

std::string settings_table_markdown();

}  // namespace mpm::config
