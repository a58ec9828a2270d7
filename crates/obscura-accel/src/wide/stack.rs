//! The traversal stack: a fixed array for the depth trees have, and a vector past it.
//!
//! A `Vec`'s push checks its capacity against memory and may call the allocator, so the
//! traversal around it keeps its values on the machine stack across the call; a fixed array
//! with the length alongside does neither. A query on an eight-wide tree stacks at most seven
//! entries per level it descends, so [`CAPACITY`] covers trees of nine levels (an eight-wide
//! tree of a million triangles has about seven); a deeper one's further entries go to the
//! vector, in the same last-in, first-out order.
//!
//! This is what `smallvec::SmallVec<[T; 64]>` is, written out because smallvec's push and pop
//! first ask whether the vector has spilled, to find its buffer and capacity, where this one's
//! array is always where it is: with smallvec the mesh comparison scene's render loop took
//! 0.7% more instructions and was no faster (docs/performance.md, round 11).

/// Entries held in the fixed array.
pub(super) const CAPACITY: usize = 64;

/// A last-in, first-out stack of traversal entries.
#[derive(Debug)]
pub(crate) struct Stack<T> {
    items: [T; CAPACITY],
    /// Entries in `items`; `spill` holds entries only when this is [`CAPACITY`].
    len: usize,
    /// The entries pushed while `items` was full, in order.
    spill: Vec<T>,
}

impl<T: Copy + Default> Stack<T> {
    /// An empty stack.
    pub(crate) fn new() -> Self {
        Stack {
            items: [T::default(); CAPACITY],
            len: 0,
            spill: Vec::new(),
        }
    }

    /// Empties the stack (keeping the vector's memory).
    #[inline(always)]
    pub(super) fn clear(&mut self) {
        self.len = 0;
        self.spill.clear();
    }

    /// Puts `entry` on top.
    #[inline(always)]
    pub(super) fn push(&mut self, entry: T) {
        match self.items.get_mut(self.len) {
            Some(slot) => {
                *slot = entry;
                self.len += 1;
            }
            None => self.push_spill(entry),
        }
    }

    /// [`Stack::push`] once the array is full: out of line, so the traversal's own loop holds
    /// no call to the allocator.
    #[cold]
    #[inline(never)]
    fn push_spill(&mut self, entry: T) {
        self.spill.push(entry);
    }

    /// Takes the top entry, or `None` when the stack is empty.
    #[inline(always)]
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == CAPACITY
            && let Some(entry) = self.spill.pop()
        {
            return Some(entry);
        }
        self.len = self.len.checked_sub(1)?;
        self.items.get(self.len).copied()
    }
}

impl<T: Copy + Default> Default for Stack<T> {
    fn default() -> Self {
        Stack::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Any run of pushes and pops, deep enough to spill, gives what a `Vec` gives.
        #[test]
        fn behaves_as_a_vec(ops in proptest::collection::vec(any::<Option<u32>>(), 0..400),
                            depth in 0usize..200) {
            let mut stack = Stack::new();
            let mut model = Vec::new();
            // Start deep, so that the ops run across the array's end.
            for k in 0..depth as u32 {
                stack.push(k);
                model.push(k);
            }
            for op in ops {
                match op {
                    Some(x) => {
                        stack.push(x);
                        model.push(x);
                    }
                    None => prop_assert_eq!(stack.pop(), model.pop()),
                }
            }
            while let Some(x) = model.pop() {
                prop_assert_eq!(stack.pop(), Some(x));
            }
            prop_assert_eq!(stack.pop(), None);
        }
    }

    #[test]
    fn clear_empties_the_array_and_the_spill() {
        let mut stack = Stack::new();
        for k in 0..(CAPACITY as u32 + 5) {
            stack.push(k);
        }
        stack.clear();
        assert_eq!(stack.pop(), None);
        stack.push(7);
        assert_eq!(stack.pop(), Some(7));
        assert_eq!(stack.pop(), None);
    }
}
