use cablemap::calibrate::diagnose::{diagnose, DiagnoseSpec};
use cablemap::calibrate::synth::{synthesize, SynthSpec};
use cablemap::calibrate::Effect;
use cablemap::model::{Actuator, SolverOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let effect = Effect::parse(&args[1]);
    let mag: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(0.0);
    let seed: u64 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(1);
    let mut truth = Actuator { ea_n: 30.0, ga_n: 1.5, ei_n_mm2: 100.0, ..Actuator::default() };
    if let Some(e) = effect { e.apply(&mut truth, mag); }
    let spec = SynthSpec { actuator: truth, seed, ..SynthSpec::default() };
    let (data, _) = synthesize(&spec, 0).unwrap();
    let t = std::time::Instant::now();
    let d = diagnose(&Actuator::default(), &SolverOptions::default(), &data, &DiagnoseSpec { holdout: Some("arc".into()), ..Default::default() }).unwrap();
    println!("{:?} verdict {} named {:?} holdout {:?} -> {:?}  ({:?})", effect, d.verdict, d.named.iter().map(|n| (n.effect, n.parameter, n.parameter_se)).collect::<Vec<_>>(), d.holdout_rms_before, d.holdout_rms_after, t.elapsed());
    println!("   baseline {:?} conv {} it {}", d.baseline.parameters.iter().map(|p| (p.value, p.se)).collect::<Vec<_>>(), d.baseline.converged, d.baseline.iterations);
    for c in &d.candidates { println!("   {:>18} {:>10.4} ± {:<8.3e} dBIC {:>9.2} rms {:.3} {}", c.effect, c.parameter, c.parameter_se, c.delta_bic, c.rms_mm, c.plausible); }
    for c in &d.second_round { println!("   2nd {:>14} {:>10.4} ± {:<8.3e} dBIC {:>9.2}", c.effect, c.parameter, c.parameter_se, c.delta_bic); }
}
