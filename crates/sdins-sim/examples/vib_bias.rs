#![allow(clippy::unwrap_used)]
use sdins_sim::random_vibration::*;
fn main() {
    let t = PsdTable::read_csv(std::path::Path::new("/work/shared/data/gnss_ins_sim/vib_psd.csv")).unwrap();
    let spec0 = RandomVibrationSpec { accel: Some(t), gyro: None, seed: 0 };
    let mut zs = vec![];
    for seed in 0..40u64 {
        let mut spec = spec0.clone(); spec.seed = seed;
        let (rv, rep) = RandomVibration::realise(&spec, 491.52, 50.0, 0).unwrap();
        let (lin, _) = rv.coefficient_power();
        let p = rep.accel.unwrap()[0].realised;
        for x in lin { zs.push(x / p - 1.0); }
    }
    let m: f64 = zs.iter().sum::<f64>() / zs.len() as f64;
    let sd = (zs.iter().map(|z| (z - m).powi(2)).sum::<f64>() / zs.len() as f64).sqrt();
    println!("mean rel dev {m:.4}, sd {sd:.4}, n {}", zs.len());
}
