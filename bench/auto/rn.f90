!----------------------------------------------------------------------
!  rn : reference problem R2 (docs/theory.md §6) with N identical
!       oscillators in a row between two rigid walls, exponential contact
!       law, harmonic base acceleration made autonomous by an appended
!       oscillator. AUTO-07p equations file (IPS=2 periodic orbits).
!       The same model, scaling and set-up as r2n2.f90, for any N >= 1:
!       N is taken from NDIM at run time, N = (NDIM - 2) / 2.
!
!  Scaling: x_i = u_i / g (clearance units), v_i = x_i' , tau = omega0 t,
!  W = Omega/omega0. In these units
!     x_i'' = -2 zeta x_i' - x_i - AS sin(W tau) + (contact forces)/(m g omega0^2)
!     contact force / (m g omega0^2) = (KA + KB sdot) exp(AG s)
!  with AS = A/(g omega0^2), KA = a/(m g omega0^2), KB = b/(m omega0),
!  AG = alpha g, s and sdot in units of g and g omega0.
!  Contacts j = 0..N (gap 1 in these units), with x_0 = x_(N+1) = 0 and
!  v_0 = v_(N+1) = 0 standing for the walls:
!     s_j = x_j - x_(j+1) - 1,  sdot_j = v_j - v_(j+1),
!     F_j = (KA + KB sdot_j) exp(AG s_j),  -F_j on body j, +F_j on body j+1
!  i.e. j = 0: left wall - body 1 (s = -x1 - 1, +F on 1), j = N: body N -
!  right wall (s = xN - 1, -F on N); at N = 2 exactly the contacts of
!  r2n2.f90 (and the same floating-point operations).
!  Appended oscillator (X, Y):
!     X' = X + W Y - X (X^2+Y^2),  Y' = -W X + Y - Y (X^2+Y^2)
!  whose stable limit cycle X = sin(W tau + phi), Y = cos(W tau + phi) is the
!  forcing (AUTO's phase condition fixes phi).
!
!  State U = (x_1..x_N, v_1..v_N, X, Y), NDIM = 2N + 2 (at N = 2 the
!  ordering of r2n2.f90: x1, x2, v1, v2, X, Y).
!  PAR(1) = W = Omega/omega0   PAR(2) = AS (forcing amplitude, scaled)
!  PAR(3) = zeta  PAR(4) = KA  PAR(5) = KB  PAR(6) = AG
!  PAR(7) = A/(g omega0^2) (the target of the amplitude homotopy)
!  PAR(11) = period (scaled time) = 2 pi / W on the branch
!  PAR(21..24) = max x_1, min x_1, max x_N, min x_N over the orbit (PVLS)
!  PAR(25) = largest Floquet multiplier modulus other than the one nearest 1
!  PAR(26) = symmetry defect max_i |max x_i + min x_(N+1-i)|: zero on the
!            symmetric branch u_(N+1-i)(t) = -u_i(t + T/2) (up to the
!            extrema being taken at collocation points), O(0.1..1) off it
!----------------------------------------------------------------------

      SUBROUTINE FUNC(NDIM,U,ICP,PAR,IJAC,F,DFDU,DFDP)
      IMPLICIT NONE
      INTEGER, INTENT(IN) :: NDIM, IJAC, ICP(*)
      DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)
      DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)
      DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM,NDIM), DFDP(NDIM,*)

      DOUBLE PRECISION X,Y,R,W,AS,Z,KA,KB,AG
      DOUBLE PRECISION XL,XR,VL,VR
      DOUBLE PRECISION S(0:NDIM/2),SD(0:NDIM/2),E(0:NDIM/2),FC(0:NDIM/2)
      INTEGER N, I, J, IX, IV

      N=(NDIM-2)/2
      IX=2*N+1
      X=U(IX); Y=U(IX+1)
      W=PAR(1); AS=PAR(2); Z=PAR(3); KA=PAR(4); KB=PAR(5); AG=PAR(6)
      R=X*X+Y*Y

!     contact j between body j (wall if j = 0) and body j+1 (wall if j = N)
      DO J=0,N
         IF(J.EQ.0)THEN
            S(J)=-U(1)-1.0D0
            SD(J)=-U(N+1)
            E(J)=EXP(AG*S(J))
            FC(J)=(KA-KB*U(N+1))*E(J)
         ELSEIF(J.EQ.N)THEN
            S(J)=U(N)-1.0D0
            SD(J)=U(2*N)
            E(J)=EXP(AG*S(J))
            FC(J)=(KA+KB*U(2*N))*E(J)
         ELSE
            XL=U(J); XR=U(J+1); VL=U(N+J); VR=U(N+J+1)
            S(J)=XL-XR-1.0D0
            SD(J)=VL-VR
            E(J)=EXP(AG*S(J))
            FC(J)=(KA+KB*(VL-VR))*E(J)
         ENDIF
      ENDDO

      DO I=1,N
         F(I)=U(N+I)
         F(N+I)=-2.0D0*Z*U(N+I)-U(I)-AS*X+FC(I-1)-FC(I)
      ENDDO
      F(IX)=X+W*Y-X*R
      F(IX+1)=-W*X+Y-Y*R

      IF(IJAC.EQ.0)RETURN

      DFDU(:,:)=0.0D0
      DO I=1,N
         DFDU(I,N+I)=1.0D0
         DFDU(N+I,I)=-1.0D0-AG*FC(I-1)-AG*FC(I)
         DFDU(N+I,N+I)=-2.0D0*Z-KB*E(I-1)-KB*E(I)
         IF(I.GT.1)THEN
            DFDU(N+I,I-1)=AG*FC(I-1)
            DFDU(N+I,N+I-1)=KB*E(I-1)
         ENDIF
         IF(I.LT.N)THEN
            DFDU(N+I,I+1)=AG*FC(I)
            DFDU(N+I,N+I+1)=KB*E(I)
         ENDIF
         DFDU(N+I,IX)=-AS
      ENDDO
      DFDU(IX,IX)=1.0D0-R-2.0D0*X*X
      DFDU(IX,IX+1)=W-2.0D0*X*Y
      DFDU(IX+1,IX)=-W-2.0D0*X*Y
      DFDU(IX+1,IX+1)=1.0D0-R-2.0D0*Y*Y

      IF(IJAC.EQ.1)RETURN

      DFDP(1:NDIM,1:6)=0.0D0
      DFDP(IX,1)=Y
      DFDP(IX+1,1)=-X
      DO I=1,N
         DFDP(N+I,2)=-X
         DFDP(N+I,3)=-2.0D0*U(N+I)
         DFDP(N+I,4)=E(I-1)-E(I)
         DFDP(N+I,5)=SD(I-1)*E(I-1)-SD(I)*E(I)
         DFDP(N+I,6)=S(I-1)*FC(I-1)-S(I)*FC(I)
      ENDDO

      END SUBROUTINE FUNC

      SUBROUTINE STPNT(NDIM,U,PAR,T)
!     Exact periodic solution at zero forcing amplitude: all bodies at
!     rest at x = 0 (the two contact forces on each body cancel exactly
!     there: both have s = -1), the oscillator on its unit circle, W = 0.5.
!     Run 1 continues PAR(2) from 0 to PAR(7).
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

      U(1:NDIM-2)=0.0D0
      U(NDIM-1)=SIN(TPI*T)
      U(NDIM)=COS(TPI*T)

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
      DOUBLE PRECISION RE, IM, AM, D, DMIN, BIG, DEF
      INTEGER I, N, NB, ITRIV

      NB=(NDIM-2)/2
      PAR(21)=GETP('MAX',1,U)
      PAR(22)=GETP('MIN',1,U)
      PAR(23)=GETP('MAX',NB,U)
      PAR(24)=GETP('MIN',NB,U)
      DEF=0.0D0
      DO I=1,NB
         DEF=MAX(DEF,ABS(GETP('MAX',I,U)+GETP('MIN',NB+1-I,U)))
      ENDDO
      PAR(26)=DEF

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
