// engine/clone_ptr.h -- an owning pointer whose copy owns a copy: T::clone() of what it points
// to. It lets a World hold its polymorphic stages (a broad phase, the solver) and still be
// copied whole, as World::snapshot does.
#pragma once

#include <memory>
#include <utility>

namespace engine {

template <class T>
class ClonePtr {
public:
    ClonePtr() = default;
    ClonePtr(std::unique_ptr<T> p) : p_(std::move(p)) {}  // NOLINT: implicit, like unique_ptr
    ClonePtr(const ClonePtr& other) : p_(other.p_ ? other.p_->clone() : nullptr) {}
    ClonePtr(ClonePtr&&) noexcept = default;
    ClonePtr& operator=(const ClonePtr& other) {
        if (this != &other) p_ = other.p_ ? other.p_->clone() : nullptr;
        return *this;
    }
    ClonePtr& operator=(ClonePtr&&) noexcept = default;
    ~ClonePtr() = default;

    T* get() const { return p_.get(); }
    T& operator*() const { return *p_; }
    T* operator->() const { return p_.get(); }
    explicit operator bool() const { return p_ != nullptr; }
    void reset() { p_.reset(); }

private:
    std::unique_ptr<T> p_;
};

}  // namespace engine
