//! Restored operator states with impossible sample counts are errors, not overflows (issue 13).

use contactlab_core::curve::Exponential;
use contactlab_core::masing::{masing_force, MasingState};
use contactlab_core::CoreError;

#[test]
fn huge_counts_are_rejected_on_restore() {
    for count in [
        1e30,
        f64::from(u32::MAX) * f64::from(u32::MAX) * 4.0,
        2f64.powi(53) + 2.0,
    ] {
        let r = MasingState::from_slice(&[0.0, 0.0, 0.0, count]);
        assert!(matches!(r, Err(CoreError::InvalidState { .. })), "{count}");
    }
    let st = MasingState::from_slice(&[0.0, 0.0, 0.0, 2f64.powi(53)]).unwrap();
    assert_eq!(st.count, 1 << 53);
}

#[test]
fn a_count_that_would_wrap_is_an_error_and_leaves_the_state() {
    let c = Exponential::new(2.5, 3.0).unwrap();
    let mut out = [0.0; 3];
    let mut st = MasingState {
        count: u64::MAX - 1,
        ..MasingState::default()
    };
    let before = st.clone();
    let r = masing_force(&c, 2.0, &[0.1, 0.2, 0.1], &mut out, &mut st);
    assert_eq!(r, Err(CoreError::TooLong { len: 3 }));
    assert_eq!(st, before);
    // Global sample indices must fit in 63 bits: up to i64::MAX it still runs.
    let last = u64::try_from(i64::MAX).unwrap();
    let mut st = MasingState {
        count: last - 3,
        ..MasingState::default()
    };
    masing_force(&c, 2.0, &[0.1, 0.2, 0.1], &mut out, &mut st).unwrap();
    assert_eq!(st.count, last);
}
