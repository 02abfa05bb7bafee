#include "app/commands.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace pl {

struct Runtime::Impl {
  ThreadPool pool;
};

void applyGlobalOptions(const GlobalOptions& global) { Progress::setEnabled(!global.quiet); }

Runtime::Runtime(const GlobalOptions& global) : impl_(new Impl{ThreadPool(global.threads)}) {
  applyGlobalOptions(global);
}
Runtime::~Runtime() = default;
int Runtime::threads() const { return impl_->pool.threads(); }

}  // namespace pl
