// Private to src/spirv: the cancellation-poll pass (cancellation_poll.cpp), run on the optimized LLVM module.
#pragma once

namespace llvm {
class Module;
}

namespace vkrt::spirv {

// Adds a poll of the executor's cancellation flag at the header of every loop (see cancellation_poll.cpp).
void addCancellationPolls(llvm::Module& mod);

}  // namespace vkrt::spirv
