/* gen_corpus_scenes - seeds of tests/fuzz/corpus_checkpoint with walls (a piston,
 * a segment) and composites (a rigid trimer, a chain), so that the fuzzer reaches
 * the WAL and CMP sections. Not built by make; run from the top directory:
 *   cc -Iinclude tests/fuzz/gen_corpus_scenes.c lib/libodhs.a $(pkg-config --libs-only-l odhs) -lm && ./a.out
 * (or link the SuiteSparse/LAPACK libraries by hand). */
#include <odhs.h>
#include <stdio.h>
#include <math.h>
int main(void){
  /* walls: 6 discs in a channel with a piston, segment; composite: 2 trimers */
  { double L[2]={12,12}, r[6], x[12]; for(int k=0;k<6;++k){ r[k]=k%2?0.6:0.5; x[2*k]=1.5+2.0*(k%3)*1.5; x[2*k+1]=3.0+3.0*(k/3);} 
    odhs_system*s; odhs_system_create(2,6,&s); if(odhs_system_set_configuration(s,L,0,r,x)) return 1;
    odhs_driver*d; odhs_driver_create(&d); double F[12]; for(int k=0;k<6;++k){F[2*k]=0.1;F[2*k+1]=-1;} odhs_driver_set_forces(d,6,2,F);
    odhs_solver*so; odhs_solver_create_by_name("dense",&so); odhs_stepper*st; odhs_stepper_create(s,d,so,&st);
    double up[2]={0,1}, dn[2]={0,-1}, v[2]={0,-0.5}, a[2]={8,9}, b[2]={11,7.5}, c[2]={6,6};
    size_t p; odhs_stepper_add_wall_plane(st,up,1.0,NULL); odhs_stepper_add_wall_plane(st,dn,-10.5,&p); odhs_stepper_set_wall_velocity(st,p,v);
    odhs_stepper_add_wall_segment(st,a,b,NULL); (void)c;
    odhs_stepper_run_until_time(st,2.0);
    if(odhs_checkpoint_write(st,"tests/fuzz/corpus_checkpoint/walls2d_n6_piston_segment.ckpt")) {printf("w1 %s\n",odhs_stepper_errmsg(st)); return 1;}
  }
  { double L[2]={10,10}, r[6]={0.5,0.5,0.5,0.6,0.6,0.6}, x[12];
    double cx[2]={3,7}, cy[2]={3,6};
    for(int t=0;t<2;++t) for(int q=0;q<3;++q){ double a=r[3*t], R=2*a/sqrt(3.0); x[2*(3*t+q)]=cx[t]+R*cos(2*3.14159265358979*q/3); x[2*(3*t+q)+1]=cy[t]+R*sin(2*3.14159265358979*q/3);} 
    odhs_system*s; odhs_system_create(2,6,&s); if(odhs_system_set_configuration(s,L,0,r,x)) return 2;
    odhs_driver*d; odhs_driver_create(&d); odhs_driver_set_shear_rate(d,1.0);
    odhs_solver*so; odhs_solver_create_by_name("dense",&so); odhs_stepper*st; odhs_stepper_create(s,d,so,&st);
    size_t b0[3]={0,1,2}, b1[3]={3,4,5}; odhs_stepper_add_rigid_body(st,3,b0); odhs_stepper_add_chain(st,3,b1);
    odhs_stepper_run_until_strain(st,0.5);
    if(odhs_checkpoint_write(st,"tests/fuzz/corpus_checkpoint/composite2d_n6_trimer_chain.ckpt")) {printf("w2 %s\n",odhs_stepper_errmsg(st)); return 2;}
  }
  return 0;
}
