// Passes and the pass registry (Binaryen style). A pass is one file in
// passes/, a small class with Name() and Run(); it opens with a comment on
// what it assumes and what it guarantees. The registry feeds --passes and
// --help; RunPasses can verify the IR after every pass and name the culprit.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "base/diagnostics.h"
#include "ir/ir.h"

namespace smtcal {

class Pass {
 public:
  virtual ~Pass() = default;
  virtual std::string_view Name() const = 0;
  virtual void Run(ir::Program& program, Diagnostics& diags) = 0;
};

struct PassInfo {
  std::string name;
  std::string description;
  std::function<std::unique_ptr<Pass>()> create;
};

// Every registered pass, in the default pipeline order.
const std::vector<PassInfo>& PassRegistry();

}  // namespace smtcal
