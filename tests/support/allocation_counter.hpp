// Counts the program's allocations through the global operator new while armed, on every thread
// (issue 31's audits of the step and render threads). allocation_counter.cpp replaces the global
// operator new and delete of the program it is compiled into (they forward to malloc and free):
// the unit and render tests only (tests/CMakeLists.txt), not the support library, whose other
// users keep the standard library's (and, under the sanitizers, their checks of new and delete).
#pragma once

namespace downpour::testing {

// Starts counting from zero.
void start_counting_allocations();
// Stops counting; returns the allocations since start_counting_allocations().
long stop_counting_allocations();

}  // namespace downpour::testing
