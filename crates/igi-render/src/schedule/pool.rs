//! [`Pool`]: memory the render threads keep from frame to frame. A frame's scratch buffers and
//! lit tiles (ARCHITECTURE.md, "A frame in two passes") hold tens of megabytes; made afresh
//! every frame, their pages were faulted in and zeroed by the kernel every frame.

use std::ops::{Deref, DerefMut};
use std::sync::{Mutex, MutexGuard};

/// Values of one kind handed out and given back, so their allocations are reused. The pool
/// holds at most what was once taken from it at the same time.
#[derive(Debug, Default)]
pub struct Pool<T> {
    free: Mutex<Vec<T>>,
}

impl<T: Default> Pool<T> {
    /// A value from the pool, or a new one if none is free. Whoever uses it must not read what
    /// an earlier user left in it.
    pub fn take(&self) -> T {
        self.free().pop().unwrap_or_default()
    }

    /// Gives values back for reuse.
    pub fn give(&self, values: impl IntoIterator<Item = T>) {
        self.free().extend(values);
    }

    /// A value lent until the returned guard drops.
    pub fn lend(&self) -> Lent<'_, T> {
        Lent { pool: self, value: Some(self.take()) }
    }

    fn free(&self) -> MutexGuard<'_, Vec<T>> {
        // A panic elsewhere cannot leave the list half-changed: a push or a pop either happened.
        self.free.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A value lent by a [`Pool`], given back when dropped.
#[derive(Debug)]
pub struct Lent<'a, T: Default> {
    pool: &'a Pool<T>,
    /// Always `Some` until the drop.
    value: Option<T>,
}

impl<T: Default> Deref for Lent<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.value.as_ref().expect("a lent value is there until it is given back")
    }
}

impl<T: Default> DerefMut for Lent<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        self.value.as_mut().expect("a lent value is there until it is given back")
    }
}

impl<T: Default> Drop for Lent<'_, T> {
    fn drop(&mut self) {
        self.pool.give(self.value.take());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lent_value_comes_back_with_its_allocation() {
        let pool = Pool::<Vec<u8>>::default();
        let address = {
            let mut lent = pool.lend();
            lent.extend_from_slice(&[1, 2, 3]);
            lent.as_ptr()
        };
        let again = pool.take();
        assert_eq!((again.as_ptr(), again.len()), (address, 3));
        assert!(pool.take().is_empty(), "a new value once the pool is empty");
    }
}
