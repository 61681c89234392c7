// The machine's load average as recorded beside benchmark figures ("1.02 0.87 0.55"; "?" when
// it cannot be read). Shared by the DDS benches so that their RESULTS.md lines read alike.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace pullout::bench {

inline std::string load_text() {
  double load[3] = {0, 0, 0};
  if (::getloadavg(load, 3) != 3) return "?";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.2f %.2f %.2f", load[0], load[1], load[2]);
  return buf;
}

}  // namespace pullout::bench
