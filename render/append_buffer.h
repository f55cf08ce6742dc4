#pragma once
// A growable array whose new entries are left for the writer: the light
// loops append a run of shadow rays at once (append(n)) and write it in
// place, where std::vector's push_back checks its capacity and moves its end
// at every entry (three vectors per shadow ray) and resize would write every
// entry twice.
#include <cassert>
#include <cstddef>
#include <cstring>
#include <memory>
#include <new>
#include <span>
#include <type_traits>

namespace raypack {

template <class T>
class AppendBuffer {
    // Entries are created by writing them (implicit-lifetime types) and
    // moved by copying bytes.
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

public:
    /// n more entries at the end, not initialised: the caller writes them.
    T* append(std::size_t n) {
        if (size_ + n > capacity_) [[unlikely]]
            grow(size_ + n);
        T* p = data_.get() + size_;
        size_ += n;
        return p;
    }
    /// append() within room reserve() made: no capacity check.
    T* append_reserved(std::size_t n) {
        assert(size_ + n <= capacity_);
        T* p = data_.get() + size_;
        size_ += n;
        return p;
    }
    /// Room for n entries in all, so that append_reserved() may follow.
    void reserve(std::size_t n) {
        if (n > capacity_) grow(n);
    }
    void push_back(const T& v) { *append(1) = v; }
    void clear() { size_ = 0; }
    /// Exactly n entries, not initialised (the caller overwrites them all).
    T* resize_for_overwrite(std::size_t n) {
        clear();
        return append(n);
    }

    std::size_t size() const { return size_; }
    std::size_t capacity() const { return capacity_; }
    bool empty() const { return size_ == 0; }
    T* data() { return data_.get(); }
    const T* data() const { return data_.get(); }
    T& operator[](std::size_t i) { return data_.get()[i]; }
    const T& operator[](std::size_t i) const { return data_.get()[i]; }
    const T* begin() const { return data(); }
    const T* end() const { return data() + size_; }
    T* begin() { return data(); }
    T* end() { return data() + size_; }
    operator std::span<const T>() const { return {data(), size_}; }
    operator std::span<T>() { return {data(), size_}; }

private:
    struct Free {
        void operator()(T* p) const { ::operator delete(p, std::align_val_t(alignof(T))); }
    };
    std::unique_ptr<T, Free> data_;
    std::size_t size_ = 0, capacity_ = 0;

    // Out of line, so that append() inlines to a compare and an add.
    [[gnu::noinline]] void grow(std::size_t need) {
        std::size_t capacity = capacity_ < 64 ? 64 : 2 * capacity_;
        while (capacity < need) capacity *= 2;
        T* p = static_cast<T*>(::operator new(capacity * sizeof(T), std::align_val_t(alignof(T))));
        if (size_ > 0) std::memcpy(static_cast<void*>(p), data_.get(), size_ * sizeof(T));
        data_.reset(p);
        capacity_ = capacity;
    }
};

/// Room for `need` entries in each of `buffers`, arrays that always grow
/// together (one entry each per item): the first's capacity stands for all.
template <class First, class... Rest>
void reserve_together(std::size_t need, First& first, Rest&... rest) {
    if (need <= first.capacity()) [[likely]]
        return;
    first.reserve(need);
    (rest.reserve(need), ...);
}

/// One more entry in each of `buffers`, within reserve_together()'s room;
/// returns its index.
template <class First, class... Rest>
inline std::size_t append_together(First& first, Rest&... rest) {
    const std::size_t k = first.size();
    first.append_reserved(1);
    (rest.append_reserved(1), ...);
    return k;
}

}  // namespace raypack
