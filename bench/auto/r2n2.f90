!----------------------------------------------------------------------
!  r2n2 : reference problem R2 (docs/theory.md §6) with
!         N = 2 pendulums between two walls, exponential contact law,
!         harmonic base acceleration made autonomous by an appended
!         oscillator. AUTO-07p equations file (IPS=2 periodic orbits).
!
!  Scaling: x_i = u_i / g (clearance units), v_i = x_i' , tau = omega0 t,
!  W = Omega/omega0. In these units
!     x_i'' = -2 zeta x_i' - x_i - AS sin(W tau) + (contact forces)/(m g omega0^2)
!     contact force / (m g omega0^2) = (KA + KB sdot) exp(AG s)
!  with AS = A/(g omega0^2), KA = a/(m g omega0^2), KB = b/(m omega0),
!  AG = alpha g, s and sdot in units of g and g omega0.
!  Contacts (gap 1 in these units):
!     0: left wall - body 1: s = -x1 - 1,  +F on 1
!     1: body 1 - body 2:    s = x1 - x2 - 1, -F on 1, +F on 2
!     2: body 2 - right wall: s = x2 - 1, -F on 2
!  Appended oscillator (U(5), U(6)) = (X, Y):
!     X' = X + W Y - X (X^2+Y^2),  Y' = -W X + Y - Y (X^2+Y^2)
!  whose stable limit cycle X = sin(W tau + phi), Y = cos(W tau + phi) is the
!  forcing (an autonomous system, so the phase phi is free; AUTO's phase
!  condition fixes it).
!
!  State U = (x1, x2, v1, v2, X, Y).
!  PAR(1) = W = Omega/omega0   PAR(2) = AS (forcing amplitude, scaled)
!  PAR(3) = zeta  PAR(4) = KA  PAR(5) = KB  PAR(6) = AG
!  PAR(11) = period (scaled time) = 2 pi / W on the branch
!  PAR(21..24) = max x1, min x1, max x2, min x2 over the orbit (PVLS)
!  PAR(25) = largest Floquet multiplier modulus other than the one nearest 1
!----------------------------------------------------------------------

      SUBROUTINE FUNC(NDIM,U,ICP,PAR,IJAC,F,DFDU,DFDP)
      IMPLICIT NONE
      INTEGER, INTENT(IN) :: NDIM, IJAC, ICP(*)
      DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)
      DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)
      DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM,NDIM), DFDP(NDIM,*)

      DOUBLE PRECISION X1,X2,V1,V2,X,Y,R,W,AS,Z,KA,KB,AG
      DOUBLE PRECISION E0,E1,E2,F0,F1,F2

      X1=U(1); X2=U(2); V1=U(3); V2=U(4); X=U(5); Y=U(6)
      W=PAR(1); AS=PAR(2); Z=PAR(3); KA=PAR(4); KB=PAR(5); AG=PAR(6)
      R=X*X+Y*Y

      E0=EXP(AG*(-X1-1.0D0))
      E1=EXP(AG*(X1-X2-1.0D0))
      E2=EXP(AG*(X2-1.0D0))
      F0=(KA-KB*V1)*E0
      F1=(KA+KB*(V1-V2))*E1
      F2=(KA+KB*V2)*E2

      F(1)=V1
      F(2)=V2
      F(3)=-2.0D0*Z*V1-X1-AS*X+F0-F1
      F(4)=-2.0D0*Z*V2-X2-AS*X+F1-F2
      F(5)=X+W*Y-X*R
      F(6)=-W*X+Y-Y*R

      IF(IJAC.EQ.0)RETURN

      DFDU(:,:)=0.0D0
      DFDU(1,3)=1.0D0
      DFDU(2,4)=1.0D0
      DFDU(3,1)=-1.0D0-AG*F0-AG*F1
      DFDU(3,2)=AG*F1
      DFDU(3,3)=-2.0D0*Z-KB*E0-KB*E1
      DFDU(3,4)=KB*E1
      DFDU(3,5)=-AS
      DFDU(4,1)=AG*F1
      DFDU(4,2)=-1.0D0-AG*F1-AG*F2
      DFDU(4,3)=KB*E1
      DFDU(4,4)=-2.0D0*Z-KB*E1-KB*E2
      DFDU(4,5)=-AS
      DFDU(5,5)=1.0D0-R-2.0D0*X*X
      DFDU(5,6)=W-2.0D0*X*Y
      DFDU(6,5)=-W-2.0D0*X*Y
      DFDU(6,6)=1.0D0-R-2.0D0*Y*Y

      IF(IJAC.EQ.1)RETURN

      DFDP(1:NDIM,1:6)=0.0D0
      DFDP(5,1)=Y
      DFDP(6,1)=-X
      DFDP(3,2)=-X
      DFDP(4,2)=-X
      DFDP(3,3)=-2.0D0*V1
      DFDP(4,3)=-2.0D0*V2

      END SUBROUTINE FUNC

      SUBROUTINE STPNT(NDIM,U,PAR,T)
!     Exact periodic solution at zero forcing amplitude: both bodies at
!     rest at x = 0 (the wall/body contact forces cancel exactly there),
!     the oscillator on its unit circle. Run 1 continues PAR(2) from 0.
      IMPLICIT NONE
      INTEGER, INTENT(IN) :: NDIM
      DOUBLE PRECISION, INTENT(INOUT) :: U(NDIM), PAR(*)
      DOUBLE PRECISION, INTENT(IN) :: T
      DOUBLE PRECISION TPI, M, OM0, ZETA, A, G, CA, CB, ALPHA, W

      M=0.227D0; OM0=7.41D0; ZETA=0.013D0; A=0.05D0; G=1.0D-3
      CA=1.0D0; CB=CA/1.2D0; ALPHA=1.3D5
      W=0.5D0
      TPI=8.0D0*ATAN(1.0D0)

      PAR(1)=W
      PAR(2)=0.0D0
      PAR(3)=ZETA
      PAR(4)=CA/(M*G*OM0**2)
      PAR(5)=CB/(M*OM0)
      PAR(6)=ALPHA*G
      PAR(7)=A/(G*OM0**2)
      PAR(11)=TPI/W

      U(1)=0.0D0
      U(2)=0.0D0
      U(3)=0.0D0
      U(4)=0.0D0
      U(5)=SIN(TPI*T)
      U(6)=COS(TPI*T)

      END SUBROUTINE STPNT

      SUBROUTINE BCND
      END SUBROUTINE BCND

      SUBROUTINE ICND
      END SUBROUTINE ICND

      SUBROUTINE FOPT
      END SUBROUTINE FOPT

      SUBROUTINE PVLS(NDIM,U,PAR)
      IMPLICIT NONE
      INTEGER, INTENT(IN) :: NDIM
      DOUBLE PRECISION, INTENT(IN) :: U(NDIM)
      DOUBLE PRECISION, INTENT(INOUT) :: PAR(*)
      DOUBLE PRECISION, EXTERNAL :: GETP
      DOUBLE PRECISION RE, IM, AM, D, DMIN, BIG
      INTEGER I, N, ITRIV

      PAR(21)=GETP('MAX',1,U)
      PAR(22)=GETP('MIN',1,U)
      PAR(23)=GETP('MAX',2,U)
      PAR(24)=GETP('MIN',2,U)

!     Floquet multipliers (IPS=2, ISP>0): NDIM of them; skip the one
!     nearest +1 (the trivial multiplier of an autonomous orbit).
      N=NINT(GETP('NDIM',0,U))
      DMIN=HUGE(1.0D0)
      ITRIV=0
      DO I=1,N
         RE=GETP('EIG',2*I-1,U)
         IM=GETP('EIG',2*I,U)
         D=(RE-1.0D0)**2+IM**2
         IF(D.LT.DMIN)THEN
            DMIN=D
            ITRIV=I
         ENDIF
      ENDDO
      BIG=0.0D0
      DO I=1,N
         IF(I.EQ.ITRIV)CYCLE
         RE=GETP('EIG',2*I-1,U)
         IM=GETP('EIG',2*I,U)
         AM=SQRT(RE**2+IM**2)
         IF(AM.GT.BIG)BIG=AM
      ENDDO
      PAR(25)=BIG

      END SUBROUTINE PVLS
