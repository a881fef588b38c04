// Counts the program's allocations through the global operator new while armed, on every thread
// (issue 31's audits of the step and render threads). Linking a program that calls these replaces
// its global operator new and delete (allocation_counter.cpp: they forward to malloc and free);
// programs that do not call them keep the library's.
#pragma once

namespace downpour::testing {

// Starts counting from zero.
void start_counting_allocations();
// Stops counting; returns the allocations since start_counting_allocations().
long stop_counting_allocations();

}  // namespace downpour::testing
