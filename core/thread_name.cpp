#include "core/thread_name.hpp"

#if defined(__linux__)
#include <pthread.h>

#include <cstring>
#endif

namespace parallax {

void NameThisThread(const char* name) {
#if defined(__linux__)
  char truncated[16] = {};
  std::strncpy(truncated, name, sizeof(truncated) - 1);
  pthread_setname_np(pthread_self(), truncated);
#else
  (void)name;
#endif
}

}  // namespace parallax
