// Running a test body in a forked child, for what must not happen to the test process
// itself (a signal, a resource limit, a fault).
#pragma once

#include <functional>

namespace vola_test {

// The child's exit status (what `body` returns; 4 when it throws), or -signal when the
// child died of one.
int in_child(const std::function<int()>& body);

}  // namespace vola_test
