//! Evaluating contacts allocates nothing: a counting global allocator (per thread) sees no
//! allocation while a `System` with a felt contact with friction and a hammer on a modal
//! string computes its derivative and its switching functions, in contact.

use mbs_core::alloc_count::{Counting, allocations_in};

use mbs_contact::laws::{Hertz, HystereticFelt, RegularizedCoulomb};
use mbs_contact::{Contact, ContactSide, Shape, StringContact, StringSpec, TautString};
use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_counter_sees_allocations() {
    let n = allocations_in(|| drop(std::hint::black_box(vec![1.0f64; 16])));
    assert!(n >= 1);
}

#[test]
fn contact_and_string_evaluations_do_not_allocate() {
    // A 10 cm arm on a pivot whose tip presses a felt pad (with friction) and whose crown
    // presses a modal string.
    let mut b = ModelBuilder::new();
    b.add_link(
        "arm",
        None,
        JointKind::Revolute,
        Placement::offset(0.0, 0.0),
        BodySpec::new(0.01, [0.05, 0.0], 1e-5),
    );
    let model = b.build().unwrap();
    let mut system = System::new(model.clone());
    let felt = Contact::new(
        &model,
        "pad",
        ContactSide::ground(vec![
            Shape::segment([0.08, -0.0015], [0.12, -0.0015]).unwrap(),
        ]),
        ContactSide::on("arm", vec![Shape::circle([0.1, 0.0], 0.002).unwrap()]),
        HystereticFelt::from_restitution(5e7, 2.0, 0.4, 1e-3).unwrap(),
    )
    .unwrap()
    .with_friction(RegularizedCoulomb::new(0.2, 1e-3).unwrap());
    system.add_element(felt).unwrap();
    let string = StringContact::new(
        &model,
        "string",
        TautString::new(&StringSpec::chaigne_askenfelt_c4()).unwrap(),
        Shape::segment([0.12, 0.0055], [0.08, 0.0055]).unwrap(),
        ContactSide::on("arm", vec![Shape::circle([0.1, 0.0], 0.006).unwrap()]),
        Hertz::new(1.35e10, 2.5).unwrap(),
    )
    .unwrap();
    system.add_element(string).unwrap();
    let mut ws = system.workspace();
    // Pressed 0.5 mm into both: the tip's pad below it, the string above the crown.
    let x = system.initial_state(0.0, &[0.0], &[0.3]).unwrap();
    let mut xdot = vec![0.0; system.state_len()];
    let mut g = vec![0.0; system.switch_len()];
    // Warm up (lazy initialisation, if any), then count.
    system.derivative(&mut ws, 0.0, &x, &mut xdot).unwrap();
    system
        .switching_functions(&mut ws, 0.0, &x, &mut g)
        .unwrap();
    assert!(
        g.len() >= 2 && g.iter().all(|&v| v < 0.0),
        "both pressed: {g:?}"
    );
    let n = allocations_in(|| {
        for _ in 0..10 {
            system.derivative(&mut ws, 0.0, &x, &mut xdot).unwrap();
            system
                .switching_functions(&mut ws, 0.0, &x, &mut g)
                .unwrap();
        }
    });
    assert_eq!(n, 0, "a contact evaluation allocated {n} times");
    assert!(xdot.iter().all(|v| v.is_finite()));
}
