//! Bindings of the kinematics core: ratio, body speeds, operating point.

use super::{Real, Whole, count, python_type};
use crate::kinematics::{
    PAPER_PRINTED_OUTPUT_TORQUE, body_speeds as core_speeds, operating_point as core_point,
    transmission_ratio as core_ratio,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Overall ratio i = input speed / output speed = 1 + (z_planet / z_sun) pins [-].
///
/// Parameters
/// ----------
/// z_sun, z_planet : int
///     Teeth of the sun and of each planet (first stage).
/// pins : int
///     Number of pins zp (the discs have zp - 1 lobes).
///
/// Returns
/// -------
/// float
///     The ratio; 57.0 for the paper (18, 42, 24).
///
/// Raises
/// ------
/// GeometryError
///     A tooth count below 1 or fewer than 3 pins.
#[pyfunction]
fn transmission_ratio(z_sun: Whole, z_planet: Whole, pins: Whole) -> PyResult<f64> {
    Ok(core_ratio(
        count("z_sun", z_sun)?,
        count("z_planet", z_planet)?,
        count("pins", pins)?,
    )?)
}

/// Angular speed of every body for an input (sun) speed, counter-clockwise positive.
///
/// Parameters
/// ----------
/// input_speed : float
///     Sun (input shaft) speed [rad/s].
/// z_sun, z_planet, pins : int
///     Tooth and pin counts (the paper's 18, 42, 24 by default).
///
/// Returns
/// -------
/// dict[str, float]
///     Speeds [rad/s]: "sun" (input), "crank_absolute" (crankshaft and planet about their own
///     axis, fixed frame), "crank_relative" (the same relative to the carrier), "disc_spin"
///     (each disc about its centre; equals the carrier), "disc_orbit" (each disc centre about
///     the reducer axis; equals crank_absolute), "carrier" (output = input / ratio).
///
/// Raises
/// ------
/// ParameterError
///     A non-finite input speed.
/// GeometryError
///     Invalid tooth or pin counts.
#[pyfunction]
#[pyo3(
    signature = (input_speed, z_sun=Whole::from(18), z_planet=Whole::from(42), pins=Whole::from(24)),
    text_signature = "(input_speed, z_sun=18, z_planet=42, pins=24)"
)]
fn body_speeds<'py>(
    py: Python<'py>,
    input_speed: Real,
    z_sun: Whole,
    z_planet: Whole,
    pins: Whole,
) -> PyResult<Bound<'py, PyDict>> {
    let s = core_speeds(
        input_speed.0,
        count("z_sun", z_sun)?,
        count("z_planet", z_planet)?,
        count("pins", pins)?,
    )?;
    let d = PyDict::new(py);
    d.set_item("sun", s.sun)?;
    d.set_item("crank_absolute", s.crank_absolute)?;
    d.set_item("crank_relative", s.crank_relative)?;
    d.set_item("disc_spin", s.disc_spin)?;
    d.set_item("disc_orbit", s.disc_orbit)?;
    d.set_item("carrier", s.carrier)?;
    Ok(d)
}

/// Lossless operating point from power, input speed and ratio.
///
/// Parameters
/// ----------
/// power : float
///     Transmitted power [W].
/// input_speed : float
///     Input (sun) speed [rad/s], non-zero.
/// ratio : float
///     Transmission ratio [-], non-zero.
///
/// Returns
/// -------
/// OperatingPoint
///     Named tuple (power [W], input_speed [rad/s], output_speed [rad/s], input_torque [N m],
///     output_torque [N m], ratio [-]) with input_torque = power / input_speed and
///     output_torque = ratio * input_torque. For the paper (112 kW, 8328 deg/s, 57):
///     770.6 N m in and 43.92 kN m out (the paper's printed 4024.9 N m is 10.3 kW at the
///     output speed; see PAPER_PRINTED_OUTPUT_TORQUE).
///
/// Raises
/// ------
/// ParameterError
///     Non-finite values or a zero speed or ratio.
#[pyfunction]
fn operating_point<'py>(
    py: Python<'py>,
    power: Real,
    input_speed: Real,
    ratio: Real,
) -> PyResult<Bound<'py, PyAny>> {
    let op = core_point(power.0, input_speed.0, ratio.0)?;
    python_type(py, "OperatingPoint")?.call1((
        op.power,
        op.input_speed,
        op.output_speed,
        op.input_torque,
        op.output_torque,
        op.ratio,
    ))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(transmission_ratio, m)?)?;
    m.add_function(wrap_pyfunction!(body_speeds, m)?)?;
    m.add_function(wrap_pyfunction!(operating_point, m)?)?;
    m.add("PAPER_PRINTED_OUTPUT_TORQUE", PAPER_PRINTED_OUTPUT_TORQUE)?;
    Ok(())
}
