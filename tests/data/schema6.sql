-- A results database of schema 6 (stickslip c47ca12, the ci study), cut to two simulations, their analyses
-- and one figure: tests/test_database.py migrates it (stickslip db migrate).
BEGIN TRANSACTION;
CREATE TABLE artifacts (
	id INTEGER NOT NULL, 
	run_id VARCHAR(16) NOT NULL, 
	direction VARCHAR NOT NULL, 
	role VARCHAR NOT NULL, 
	path VARCHAR NOT NULL, 
	sha256 VARCHAR(64) NOT NULL, 
	bytes INTEGER NOT NULL, 
	format VARCHAR, 
	made_by VARCHAR(16), 
	PRIMARY KEY (id), 
	FOREIGN KEY(run_id) REFERENCES runs (run_id) ON DELETE CASCADE
);
INSERT INTO "artifacts" VALUES(5,'9f41c37b7684f0ef','input','simulation','results/ci/sim/lever/2ef280fede571fe0.h5','34129c023fc558c2c5333f7e74aa5eaa08d66f929ca3929269679e054c143267',986410,'timeseries','2ef280fede571fe0');
INSERT INTO "artifacts" VALUES(6,'9f41c37b7684f0ef','output','output','results/ci/events/experiment-events/lever/2ef280fede571fe0.h5','406e1f27d66bfe7ba6c9432e215fc18a75cec4d6d7bf27986cf1d57d1cfac872',32174,'event-table',NULL);
INSERT INTO "artifacts" VALUES(11,'86bcb5dd133c8ffb','input','simulation','results/ci/sim/fem/20013c0b980c6ecd.h5','2b1f14ddd2bfc041b2a1ed4c16b5d55c299aeedf946e7db3b53151df21888126',453280,'fem-run','20013c0b980c6ecd');
INSERT INTO "artifacts" VALUES(12,'86bcb5dd133c8ffb','output','output','results/ci/events/numerical-events/fem/20013c0b980c6ecd.h5','7068c3161c662c72308f697ba4cf3a5bc7f714847a2ef11fd572125564657ce1',45571,'event-table',NULL);
INSERT INTO "artifacts" VALUES(85,'0de3057744279c41','input','format:mesh','results/ci/mesh/6fe22e7a017bbf44.h5','54d701ba8aaecd8551e425c40402182918a9965ed696f7cfde935fd3027b9156',12303,'mesh','6fe22e7a017bbf44');
INSERT INTO "artifacts" VALUES(86,'0de3057744279c41','output','pdf','results/ci/figures/figS-mesh.pdf','5ee77f31b356b03f0f626a1603cb2d7e313c2b4bc9f3a35a07113de7b6afff8c',11082,NULL,NULL);
INSERT INTO "artifacts" VALUES(87,'0de3057744279c41','output','png','results/ci/figures/figS-mesh.png','f7dbaa918a774923432ab5d803bbf98d4b935f7a864ba24aa01b37564b19591e',14252,NULL,NULL);
INSERT INTO "artifacts" VALUES(117,'20013c0b980c6ecd','input','mesh','results/ci/mesh/6fe22e7a017bbf44.h5','54d701ba8aaecd8551e425c40402182918a9965ed696f7cfde935fd3027b9156',12303,'mesh','6fe22e7a017bbf44');
INSERT INTO "artifacts" VALUES(118,'20013c0b980c6ecd','output','output','results/ci/sim/fem/20013c0b980c6ecd.h5','2b1f14ddd2bfc041b2a1ed4c16b5d55c299aeedf946e7db3b53151df21888126',453280,'fem-run',NULL);
INSERT INTO "artifacts" VALUES(121,'2ef280fede571fe0','output','output','results/ci/sim/lever/2ef280fede571fe0.h5','34129c023fc558c2c5333f7e74aa5eaa08d66f929ca3929269679e054c143267',986410,'timeseries',NULL);
CREATE TABLE figures (
	run_id VARCHAR(16) NOT NULL, 
	figure VARCHAR NOT NULL, 
	pdf VARCHAR NOT NULL, 
	png VARCHAR, 
	PRIMARY KEY (run_id), 
	FOREIGN KEY(run_id) REFERENCES runs (run_id) ON DELETE CASCADE
);
INSERT INTO "figures" VALUES('0de3057744279c41','figS-mesh','results/ci/figures/figS-mesh.pdf','results/ci/figures/figS-mesh.png');
CREATE TABLE run_periodicity (
	analysis_run_id VARCHAR(16) NOT NULL, 
	simulation_run_id VARCHAR(16) NOT NULL, 
	analysis VARCHAR NOT NULL, 
	slips INTEGER NOT NULL, 
	multi INTEGER NOT NULL, 
	spanning INTEGER NOT NULL, 
	interval_cv FLOAT, 
	drop_cv FLOAT, 
	multi_fraction FLOAT, 
	spanning_fraction FLOAT, 
	alternation_cv FLOAT, 
	runs_z FLOAT, 
	PRIMARY KEY (analysis_run_id), 
	FOREIGN KEY(analysis_run_id) REFERENCES runs (run_id) ON DELETE CASCADE
);
INSERT INTO "run_periodicity" VALUES('86bcb5dd133c8ffb','20013c0b980c6ecd','numerical-events',3,0,3,7.13145210067012702559e-01,6.73124834854177511722e-01,0.0,1.0,NULL,NULL);
CREATE TABLE runs (
	run_id VARCHAR(16) NOT NULL, 
	kind VARCHAR NOT NULL, 
	plugin VARCHAR NOT NULL, 
	plugin_version VARCHAR NOT NULL, 
	code_hash VARCHAR NOT NULL, 
	package_version VARCHAR NOT NULL, 
	git_commit VARCHAR, 
	git_dirty BOOLEAN, 
	params TEXT NOT NULL, 
	seed INTEGER, 
	threads INTEGER NOT NULL, 
	python_version VARCHAR NOT NULL, 
	numpy_version VARCHAR, 
	numba_version VARCHAR, 
	h5py_version VARCHAR, 
	versions TEXT NOT NULL, 
	host VARCHAR NOT NULL, 
	started_at VARCHAR NOT NULL, 
	finished_at VARCHAR NOT NULL, 
	wall_time_s FLOAT NOT NULL, 
	peak_memory_mib FLOAT NOT NULL, 
	record_path VARCHAR NOT NULL, 
	PRIMARY KEY (run_id)
);
INSERT INTO "runs" VALUES('9f41c37b7684f0ef','analysis','experiment-events','2','b06410b2df673afc','0.1.0','c47ca122cf1dd54c345f25d56148fd2c9be48aaa',0,'{"average_frames": 5, "force_window": 1.0, "min_frames": 3, "position_frames": 5, "slow_slip_drift": 0.003, "t0": 1.0, "t_exclude": 100.0, "threshold": 0.02}',NULL,1,'3.11.7','2.4.6','0.68.1','3.16.0','{"h5py": "3.16.0", "llvmlite": "0.50.0", "matplotlib": "3.11.2", "numba": "0.68.1", "numpy": "2.4.6", "pandas": "3.1.1", "platform": "Linux-6.18.44-fc-v595-x86_64-with-glibc2.36", "python": "3.11.7", "qdldl": "0.1.9.post1", "scipy": "1.17.1", "snakemake": "9.27.1", "sqlalchemy": "2.0.58", "threadpoolctl": "3.8.0"}','vm','2026-11-28T18:36:25.856+00:00','2026-11-28T18:36:25.999+00:00',0.142635,283.285,'results/ci/events/experiment-events/lever/2ef280fede571fe0.provenance.json');
INSERT INTO "runs" VALUES('86bcb5dd133c8ffb','analysis','numerical-events','2','32dd32befcbe754f','0.1.0','c47ca122cf1dd54c345f25d56148fd2c9be48aaa',0,'{}',NULL,1,'3.11.7','2.4.6','0.68.1','3.16.0','{"h5py": "3.16.0", "llvmlite": "0.50.0", "matplotlib": "3.11.2", "numba": "0.68.1", "numpy": "2.4.6", "pandas": "3.1.1", "platform": "Linux-6.18.44-fc-v595-x86_64-with-glibc2.36", "python": "3.11.7", "qdldl": "0.1.9.post1", "scipy": "1.17.1", "snakemake": "9.27.1", "sqlalchemy": "2.0.58", "threadpoolctl": "3.8.0"}','vm','2026-11-28T18:38:12.753+00:00','2026-11-28T18:38:12.791+00:00',0.0386,283.785,'results/ci/events/numerical-events/fem/20013c0b980c6ecd.provenance.json');
INSERT INTO "runs" VALUES('0de3057744279c41','figure','figS-mesh','1','fa96ca4dd5e6bad4','0.1.0','c47ca122cf1dd54c345f25d56148fd2c9be48aaa',0,'{"N": 0, "plates": 2, "zoom_width": 60}',NULL,1,'3.11.7','2.4.6','0.68.1','3.16.0','{"h5py": "3.16.0", "llvmlite": "0.50.0", "matplotlib": "3.11.2", "numba": "0.68.1", "numpy": "2.4.6", "pandas": "3.1.1", "platform": "Linux-6.18.44-fc-v595-x86_64-with-glibc2.36", "python": "3.11.7", "qdldl": "0.1.9.post1", "scipy": "1.17.1", "snakemake": "9.27.1", "sqlalchemy": "2.0.58", "threadpoolctl": "3.8.0"}','vm','2026-11-28T18:36:20.584+00:00','2026-11-28T18:36:21.273+00:00',0.688877,282.91,'results/ci/figures/figS-mesh.provenance.json');
INSERT INTO "runs" VALUES('20013c0b980c6ecd','solver','fem','4','fad1949462bdb883','0.1.0','c47ca122cf1dd54c345f25d56148fd2c9be48aaa',0,'{"G": 1.0, "K": 4.5, "N": 9, "deps": 0.0001, "drive": "fixed-lever", "dt_scale": 1.0, "eps0": 5e-05, "eps_offset": 1e-06, "k_drive": 0.01472, "lever_height": 10.0, "margin": 5, "max_increments": 200, "max_iter": 10000000, "nchunk": 6000, "niter_tol": 20, "plates": 2, "quiet_steps": 0, "relaxation": "dynamic", "rho": 1.0, "seed": 1, "tol": 1e-05, "weibull_k": 2.0, "window": 1000, "yield_strains": "extend"}',1,1,'3.11.7','2.4.6','0.68.1','3.16.0','{"h5py": "3.16.0", "llvmlite": "0.50.0", "matplotlib": "3.11.2", "numba": "0.68.1", "numpy": "2.4.6", "pandas": "3.1.1", "platform": "Linux-6.18.44-fc-v595-x86_64-with-glibc2.36", "python": "3.11.7", "qdldl": "0.1.9.post1", "scipy": "1.17.1", "snakemake": "9.27.1", "sqlalchemy": "2.0.58", "threadpoolctl": "3.8.0"}','vm','2026-11-28T18:36:29.692+00:00','2026-11-28T18:38:11.138+00:00',101.446385,592.949,'results/ci/sim/fem/20013c0b980c6ecd.provenance.json');
INSERT INTO "runs" VALUES('2ef280fede571fe0','solver','lever','2','d280f11d2fbc661f','0.1.0','c47ca122cf1dd54c345f25d56148fd2c9be48aaa',0,'{"B": [0.03, 0.018, 0.039, 0.023, 0.034], "H": 100.0, "T0": 1.0, "V": 0.01, "a": 0, "creep_onset": 0.8, "creep_velocity": [0.0015, 0.00075, 0.0, 0.0, 0.0], "duration": 2000.0, "force_noise": 0.01, "force_rate": 50.0, "frame_rate": 5.0, "gamma_start": -0.3, "h": 10.0, "k_spring": 55.0, "mu_d": [0.35], "n": 3, "n_slabs": 5, "normal_force": 49.0, "position_noise": 0.002, "protocol": "stack", "seed": 1, "slip_duration": 0.2, "strength_offset": 0.08, "threshold_noise": 0.015, "trigger_margin": 0.0}',1,1,'3.11.7','2.4.6','0.68.1','3.16.0','{"h5py": "3.16.0", "llvmlite": "0.50.0", "matplotlib": "3.11.2", "numba": "0.68.1", "numpy": "2.4.6", "pandas": "3.1.1", "platform": "Linux-6.18.44-fc-v595-x86_64-with-glibc2.36", "python": "3.11.7", "qdldl": "0.1.9.post1", "scipy": "1.17.1", "snakemake": "9.27.1", "sqlalchemy": "2.0.58", "threadpoolctl": "3.8.0"}','vm','2026-11-28T18:36:21.309+00:00','2026-11-28T18:36:22.431+00:00',1.121836,283.035,'results/ci/sim/lever/2ef280fede571fe0.provenance.json');
CREATE TABLE schema_info (
	"key" VARCHAR NOT NULL, 
	value VARCHAR NOT NULL, 
	PRIMARY KEY ("key")
);
INSERT INTO "schema_info" VALUES('schema_version','6');
INSERT INTO "schema_info" VALUES('package_version','0.1.0');
CREATE TABLE simulations (
	run_id VARCHAR(16) NOT NULL, 
	solver VARCHAR NOT NULL, 
	path VARCHAR NOT NULL, 
	format VARCHAR NOT NULL, 
	source VARCHAR, 
	protocol VARCHAR, 
	n INTEGER, 
	a INTEGER, 
	plates INTEGER, 
	blocks INTEGER, 
	k_drive FLOAT, 
	phi FLOAT, 
	regime VARCHAR, 
	seed INTEGER, 
	temperature FLOAT, 
	attempt_rate FLOAT, 
	drive_rate FLOAT, 
	junction_strengthening FLOAT, 
	junction_glass_temperature FLOAT, 
	junction_attempt_rate FLOAT, 
	PRIMARY KEY (run_id), 
	FOREIGN KEY(run_id) REFERENCES runs (run_id) ON DELETE CASCADE
);
INSERT INTO "simulations" VALUES('20013c0b980c6ecd','fem','results/ci/sim/fem/20013c0b980c6ecd.h5','fem-run','numerical',NULL,1,NULL,2,9,0.01472,4.99939620818741742389e-07,'compliant',1,0.0,NULL,NULL,NULL,NULL,NULL);
INSERT INTO "simulations" VALUES('2ef280fede571fe0','lever','results/ci/sim/lever/2ef280fede571fe0.h5','timeseries','experimental','stack',3,0,NULL,NULL,NULL,NULL,NULL,1,NULL,NULL,NULL,NULL,NULL,NULL);
CREATE TABLE slip_events (
	id INTEGER NOT NULL, 
	analysis_run_id VARCHAR(16) NOT NULL, 
	simulation_run_id VARCHAR(16) NOT NULL, 
	analysis VARCHAR NOT NULL, 
	solver VARCHAR NOT NULL, 
	source VARCHAR, 
	event INTEGER NOT NULL, 
	interface INTEGER, 
	slip FLOAT, 
	dmu FLOAT, 
	multi BOOLEAN, 
	time FLOAT, 
	increment INTEGER, 
	extra TEXT, 
	PRIMARY KEY (id), 
	FOREIGN KEY(analysis_run_id) REFERENCES runs (run_id) ON DELETE CASCADE
);
INSERT INTO "slip_events" VALUES(36,'9f41c37b7684f0ef','2ef280fede571fe0','experiment-events','lever','experimental',3,1,0.0609509632468872,2.04237929315204680413e-01,0,131.5,NULL,'{"t_start": 130.6, "t_end": 132.4, "dF": 2.001531707289006, "T": 36.19999999999999, "dR_from_dF": 0.060652475978454724, "B_a": 0.05690570217792517, "drift": 0.009240225644225664, "slow_slip_before": true}');
INSERT INTO "slip_events" VALUES(37,'9f41c37b7684f0ef','2ef280fede571fe0','experiment-events','lever','experimental',4,1,5.90380279889362036271e-02,1.92153153930195358389e-01,0,167.3,NULL,'{"t_start": 166.4, "t_end": 168.2, "dF": 1.8831009085159147, "T": 35.80000000000001, "dR_from_dF": 0.057063663894421655, "B_a": 0.05370484972245962, "drift": 0.009205356061465775, "slow_slip_before": true}');
INSERT INTO "slip_events" VALUES(38,'9f41c37b7684f0ef','2ef280fede571fe0','experiment-events','lever','experimental',5,2,9.26841970152962879581e-02,2.07013863830312061509e-01,0,193.3,NULL,'{"t_start": 192.4, "t_end": 194.2, "dF": 2.5359198319213228, "T": 128.0, "dR_from_dF": 0.09221526661532083, "B_a": 0.04266541067760777, "drift": 0.011185545960756826, "slow_slip_before": true}');
INSERT INTO "slip_events" VALUES(39,'9f41c37b7684f0ef','2ef280fede571fe0','experiment-events','lever','experimental',6,2,0.0696558026759706,1.5664645070201441146e-01,0,222.3,NULL,'{"t_start": 221.4, "t_end": 223.2, "dF": 1.9189190210996765, "T": 29.0, "dR_from_dF": 0.06977887349453368, "B_a": 0.046519955065143066, "drift": 0.0018525680211496365, "slow_slip_before": false}');
INSERT INTO "slip_events" VALUES(111,'86bcb5dd133c8ffb','20013c0b980c6ecd','numerical-events','fem','numerical',0,1,NULL,1.32300717818219659704e+00,0,NULL,2,'{"dgamma": null}');
INSERT INTO "slip_events" VALUES(112,'86bcb5dd133c8ffb','20013c0b980c6ecd','numerical-events','fem','numerical',1,1,NULL,4.06822566492668125093e-01,0,NULL,142,'{"dgamma": 65.69652189785197}');
INSERT INTO "slip_events" VALUES(113,'86bcb5dd133c8ffb','20013c0b980c6ecd','numerical-events','fem','numerical',2,1,NULL,5.08357126468690356801e-01,0,NULL,176,'{"dgamma": 21.650204448748767}');
CREATE INDEX ix_runs_kind ON runs (kind);
CREATE INDEX ix_runs_plugin ON runs (plugin);
CREATE INDEX ix_artifacts_run_id ON artifacts (run_id);
CREATE INDEX ix_artifacts_path ON artifacts (path);
CREATE INDEX ix_artifacts_sha256 ON artifacts (sha256);
CREATE INDEX ix_artifacts_made_by ON artifacts (made_by);
CREATE INDEX ix_simulations_phi ON simulations (phi);
CREATE INDEX ix_simulations_n ON simulations (n);
CREATE INDEX ix_simulations_regime ON simulations (regime);
CREATE INDEX ix_simulations_solver ON simulations (solver);
CREATE INDEX ix_slip_events_sim_interface ON slip_events (simulation_run_id, interface);
CREATE INDEX ix_slip_events_source ON slip_events (source);
CREATE INDEX ix_slip_events_interface ON slip_events (interface);
CREATE INDEX ix_slip_events_solver ON slip_events (solver);
CREATE INDEX ix_slip_events_analysis ON slip_events (analysis);
CREATE INDEX ix_slip_events_analysis_run_id ON slip_events (analysis_run_id);
CREATE INDEX ix_slip_events_simulation_run_id ON slip_events (simulation_run_id);
CREATE INDEX ix_run_periodicity_simulation_run_id ON run_periodicity (simulation_run_id);
CREATE INDEX ix_figures_figure ON figures (figure);
CREATE VIEW slip_events_full AS SELECT e.*, s.protocol, s.n, s.a, s.plates, s.blocks, s.k_drive, s.phi, s.regime, s.seed, s.temperature, s.attempt_rate, s.drive_rate, s.junction_strengthening, s.junction_glass_temperature, s.junction_attempt_rate FROM slip_events AS e LEFT JOIN simulations AS s ON s.run_id = e.simulation_run_id;
CREATE VIEW periodicity_full AS SELECT p.*, s.solver, s.n, s.plates, s.blocks, s.k_drive, s.phi, s.regime, s.seed, json_extract(r.params, '$.dt_scale') AS dt_scale FROM run_periodicity AS p LEFT JOIN simulations AS s ON s.run_id = p.simulation_run_id LEFT JOIN runs AS r ON r.run_id = p.simulation_run_id;
COMMIT;
