#include "app/commands.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace pl {

struct Runtime::Impl {
  ThreadPool pool;
};

Runtime::Runtime(const GlobalOptions& global) : impl_(new Impl{ThreadPool(global.threads)}) {
  Progress::setEnabled(!global.quiet);
}
Runtime::~Runtime() = default;
int Runtime::threads() const { return impl_->pool.threads(); }

}  // namespace pl
