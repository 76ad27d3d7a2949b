//! Cutting one array into disjoint consecutive pieces, so that threads can fill a
//! result in place, each its own piece, rather than each building a vector that is
//! copied into the whole afterwards (a second pass over memory, and its page faults);
//! and comparing arrays bit for bit, as the caches of repeated evaluations do.

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

/// The pieces of [`pieces`] that are not empty, each with its place in `lengths`: for
/// a matrix whose few rows hold anything.
pub(crate) fn filled_pieces<T>(
    v: &mut [T],
    lengths: impl IntoIterator<Item = usize>,
) -> Vec<(usize, &mut [T])> {
    let mut rest = v;
    let mut out = Vec::new();
    for (i, n) in lengths.into_iter().enumerate() {
        if n > 0 {
            out.push((i, take(&mut rest, n)));
        }
    }
    out
}

/// Whether `a` and `b` hold the same numbers bit for bit (a cache's key: `-0.0` and
/// `0.0` differ, and a NaN equals itself).
pub(crate) fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(a, b)| a.to_bits() == b.to_bits())
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
        let f = super::filled_pieces(&mut v, [0, 2, 0, 1]);
        assert_eq!(f.len(), 2);
        assert_eq!((f[0].0, &*f[0].1), (1, &[0, 1][..]));
        assert_eq!((f[1].0, &*f[1].1), (3, &[2][..]));
    }

    #[test]
    fn same_bits_tells_signed_zeros_apart_and_lengths_too() {
        assert!(super::same_bits(&[1.0, f64::NAN], &[1.0, f64::NAN]));
        assert!(!super::same_bits(&[0.0], &[-0.0]));
        assert!(!super::same_bits(&[1.0], &[1.0, 2.0]));
        assert!(!super::same_bits(&[1.0], &[1.0 + f64::EPSILON]));
    }
}
