//! Cutting one array into disjoint consecutive pieces, so that threads can fill a
//! result in place, each its own piece, rather than each building a vector that is
//! copied into the whole afterwards (a second pass over memory, and its page faults).

/// The first `n` of `*rest`, which keeps the others.
pub(crate) fn take<'a, T>(rest: &mut &'a mut [T], n: usize) -> &'a mut [T] {
    let (head, tail) = std::mem::take(rest).split_at_mut(n);
    *rest = tail;
    head
}

/// `v` cut into consecutive pieces of the given lengths (which must not add up to
/// more than `v.len()`).
pub(crate) fn pieces<T>(v: &mut [T], lengths: impl IntoIterator<Item = usize>) -> Vec<&mut [T]> {
    let mut rest = v;
    lengths.into_iter().map(|n| take(&mut rest, n)).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn pieces_follow_each_other_and_cover_their_lengths() {
        let mut v: Vec<u32> = (0..10).collect();
        let p = super::pieces(&mut v, [3, 0, 4]);
        assert_eq!(p.len(), 3);
        assert_eq!(&*p[0], &[0, 1, 2]);
        assert!(p[1].is_empty());
        assert_eq!(&*p[2], &[3, 4, 5, 6]);
    }
}
