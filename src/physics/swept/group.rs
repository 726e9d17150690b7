//! A stable counting sort into buckets: the one way `swept` indexes pairs
//! by slot (a slot's meeting pairs, its partners).

/// Groups `items` by key in `0..keys`, keeping their order within a key:
/// `out[starts[k]..starts[k + 1]]` are the items of key `k`.
pub(super) fn group<T: Copy + Default>(
    starts: &mut Vec<u32>,
    out: &mut Vec<T>,
    keys: usize,
    items: impl Iterator<Item = (u32, T)> + Clone,
) {
    starts.clear();
    starts.resize(keys + 1, 0);
    // `for_each`, not `for`: chained pair lists are then walked list by
    // list, not item by item through the chain.
    items.clone().for_each(|(k, _)| starts[k as usize + 1] += 1);
    for k in 0..keys {
        starts[k + 1] += starts[k];
    }
    out.clear();
    out.resize(starts[keys] as usize, T::default());
    items.for_each(|(k, v)| {
        let at = &mut starts[k as usize];
        out[*at as usize] = v;
        *at += 1;
    });
    // Placing moved each start to the next key's; shift back.
    for k in (1..=keys).rev() {
        starts[k] = starts[k - 1];
    }
    starts[0] = 0;
}

#[cfg(test)]
mod tests {
    use super::group;

    #[test]
    fn items_land_in_their_key_in_their_order() {
        let items = [(2, 'a'), (0, 'b'), (2, 'c'), (3, 'd'), (0, 'e')];
        let (mut starts, mut out) = (Vec::new(), Vec::new());
        group(&mut starts, &mut out, 4, items.iter().copied());
        assert_eq!(starts, [0, 2, 2, 4, 5]);
        assert_eq!(out, ['b', 'e', 'a', 'c', 'd']);
    }
}
