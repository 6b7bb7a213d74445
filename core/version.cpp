#include "core/version.h"

#include "core/version_info.h"

namespace pneufem {

std::string version_string() { return std::string(PNEUFEM_VERSION) + " (" + PNEUFEM_GIT + ")"; }

}  // namespace pneufem
