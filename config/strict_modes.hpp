// The service's check on the files that decide what it trusts, as sshd's
// StrictModes: a config or plant file that another user could have written
// is refused, because whoever can write it can blind the monitor (an
// inflated noise model, a plant equal to the faulty plant).
#pragma once

#include <string>

namespace mpm::config {

// Throws ConfigError naming `path` and its mode or owner when group or others
// may write it, or when it is owned by a user other than root and the
// effective user. `what` says which file it is ("config", "plant").
void check_strict_modes(const std::string& path, const char* what);

}  // namespace mpm::config
