#include "config/strict_modes.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <sys/stat.h>
#include <unistd.h>

#include "config/plant_loader.hpp"

namespace mpm::config {

void check_strict_modes(const std::string& path, const char* what) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0)
    throw ConfigError(path + ": cannot inspect " + what + " file: " + std::strerror(errno));
  const unsigned mode = info.st_mode & 07777u;
  if (mode & (S_IWGRP | S_IWOTH)) {
    char octal[8];
    std::snprintf(octal, sizeof octal, "%04o", mode);
    throw ConfigError(path + ": " + what + " file has mode " + octal +
                      ": group or others may write it; refusing it as sshd's StrictModes would "
                      "(chmod go-w " + path + ")");
  }
  const uid_t self = ::geteuid();
  if (info.st_uid != 0 && info.st_uid != self)
    throw ConfigError(path + ": " + what + " file is owned by uid " + std::to_string(info.st_uid) +
                      ", neither root nor this service's user (uid " + std::to_string(self) +
                      "); refusing it as sshd's StrictModes would");
}

}  // namespace mpm::config
